// A face's corner shifted by its y offset in registers (shifted_corner.h) against p + Vector2d(0, dy).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "../src/flatten_internal.h"
#include "../src/shifted_corner.h"

namespace cf {
namespace {

using flat_detail::V2;

bool same_bits(const V2& a, const V2& b) { return std::memcmp(a.data(), b.data(), 2 * sizeof(double)) == 0; }

// Random positions and offsets (whole periods and not), signed zeros, subnormals, infinities and NaN.
std::vector<double> corner_values() {
  const double inf = std::numeric_limits<double>::infinity(), tiny = std::numeric_limits<double>::denorm_min();
  std::vector<double> values = {0.0, -0.0, tiny, -tiny, 1.0, -1.0, 1e300, -1e300, inf, -inf,
                                std::numeric_limits<double>::quiet_NaN(), 123.456, 62.83185307179586};
  std::mt19937_64 rng(36);
  std::uniform_real_distribution<double> u(-500.0, 500.0);
  for (int i = 0; i < 2000; ++i) values.push_back(u(rng));
  return values;
}

// f(p, dy) against want(p, dy) by memcmp over pairs of corner_values(); the number compared.
template <class F, class Want>
int compare_over_values(F&& f, Want&& want) {
  const std::vector<double> values = corner_values();
  int compared = 0;
  for (std::size_t i = 0; i < values.size(); ++i)
    for (std::size_t j = 0; j < 40; ++j) {
      const V2 p(values[i], values[(i * 7 + j) % values.size()]);
      const double dy = values[(i * 13 + j * 3) % values.size()];
      EXPECT_TRUE(same_bits(f(p, dy), want(p, dy))) << p.transpose() << " " << dy;
      ++compared;
    }
  return compared;
}

// shifted_corner(p, dy) is p + V2(0, dy) bit for bit over those values (-0 + 0 is +0 in x, as the
// vector sum makes it).
TEST(ShiftedCorner, IsTheVectorSumsBits) {
  const int compared = compare_over_values([](const V2& p, double dy) { return flat_detail::shifted_corner(p, dy); },
                                           [](const V2& p, double dy) { return V2(p + V2(0, dy)); });
  EXPECT_FALSE(std::signbit(flat_detail::shifted_corner(V2(-0.0, 1.0), 0.0).x()));  // -0 + 0: +0
  EXPECT_GT(compared, 80000);
}

// unshifted_corner(p, dy) is p - V2(0, dy) bit for bit over the same values (-0 - 0 stays -0 in x;
// +0 - 0 is +0).
TEST(ShiftedCorner, UnshiftedIsTheVectorDifferencesBits) {
  const int compared = compare_over_values([](const V2& p, double dy) { return flat_detail::unshifted_corner(p, dy); },
                                           [](const V2& p, double dy) { return V2(p - V2(0, dy)); });
  EXPECT_TRUE(std::signbit(flat_detail::unshifted_corner(V2(-0.0, 1.0), 0.0).x()));  // -0 - 0: -0
  EXPECT_GT(compared, 80000);
}

// Embedding::corners() and area2() are the vector sums' corners and area to the bit on a face whose
// corners carry offsets of a whole period (the cylinder's seam) and none.
TEST(ShiftedCorner, EmbeddingCornersAreTheVectorSums) {
  flat_detail::Surface s;
  flat_detail::Embedding emb;
  s.p = {flat_detail::V3(0, 0, 0), flat_detail::V3(1, 0, 0), flat_detail::V3(0, 1, 0)};
  s.t = {{0, 1, 2}, {0, 1, 2}};
  emb.pos = {V2(-0.0, 31.4), V2(1.37, 62.7), V2(0.21, 0.1)};
  emb.dy = {{0.0, -62.83185307179586, 0.0}, {0.0, 0.0, 0.0}};
  for (int f = 0; f < 2; ++f) {
    const auto c = emb.corners(s, f);
    for (int k = 0; k < 3; ++k) {
      const V2 want = emb.pos[std::size_t(s.t[std::size_t(f)][std::size_t(k)])] + V2(0, emb.dy[std::size_t(f)][std::size_t(k)]);
      EXPECT_TRUE(same_bits(c[std::size_t(k)], want)) << f << " " << k;
    }
    const V2 a = c[1] - c[0], b = c[2] - c[0];
    EXPECT_EQ(emb.area2(s, f), 0.5 * (a.x() * b.y() - a.y() * b.x()));
  }
}

}  // namespace
}  // namespace cf
