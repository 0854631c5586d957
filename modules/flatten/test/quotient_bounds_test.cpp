// The area energy's skipped divisions (quotient_bounds.h): the inside test by products never says
// "inside" for a quotient LogRatioExcess would not return +0 for, and 0 / d is 0 with its sign; the
// energy's gradients are the division formulas' to the bit.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "../src/conformal_area_energy.h"
#include "../src/quotient_bounds.h"
#include "squeezed_grid.h"

namespace cf {
namespace {

using flat_detail::V2;

std::uint64_t bits(double x) {
  std::uint64_t b;
  std::memcpy(&b, &x, sizeof b);
  return b;
}

constexpr double kInf = std::numeric_limits<double>::infinity();

// Denominators: specials (0, negative, subnormal, smallest normal, huge, infinite, NaN) and random
// ones over 600 decades.
std::vector<double> denominators() {
  std::vector<double> d = {0.0, -0.0, -1.0, std::numeric_limits<double>::denorm_min(), std::numeric_limits<double>::min(),
                           1e-300, 1e-12, 0.37, 1.0, 3.3e5, 1e300, std::numeric_limits<double>::max(), kInf,
                           std::numeric_limits<double>::quiet_NaN()};
  std::mt19937_64 rng(37);
  std::uniform_real_distribution<double> exponent(-300.0, 300.0);
  for (int k = 0; k < 300; ++k) d.push_back(std::pow(10.0, exponent(rng)));
  return d;
}

// Numerators for d: 64 ulps either side of edge x d for each bound edge (the bounds, LogRatioExcess's
// rounded margins, twice the margins), random ratios around [lo, hi], and specials.
std::vector<double> numerators(double lo, double hi, double d, std::mt19937_64& rng) {
  const double m = flat_detail::LogRatioExcess::kInsideMargin;
  std::vector<double> n = {0.0, -0.0, -d, kInf, -kInf, std::numeric_limits<double>::quiet_NaN()};
  for (double edge : {lo, hi, lo * (1 + m), hi * (1 - m), lo * (1 + 2 * m), hi * (1 - 2 * m)}) {
    double x = edge * d;
    for (int k = 0; k < 64; ++k) x = std::nextafter(x, 0.0);
    for (int k = 0; k < 128; ++k, x = std::nextafter(x, kInf)) n.push_back(x);
  }
  std::uniform_real_distribution<double> r(0.5 * lo, 2 * hi);
  for (int k = 0; k < 200; ++k) n.push_back(r(rng) * d);
  return n;
}

// For bound pairs wide, narrow and empty, over ~10^6 (n, d) pairs: whenever SurelyInside says
// inside, LogRatioExcess(n / d) is +0 (so the skipped division changes no bit); and it says inside
// for most pairs whose ratio lies well within the bounds (it is not a test that never fires).
TEST(QuotientBounds, SurelyInsideOnlyWhereTheExcessIsZero) {
  std::mt19937_64 rng(26);
  for (const auto& [lo, hi] :
       std::vector<std::pair<double, double>>{{0.4, 3.0}, {0.1, 10.0}, {0.999, 1.001}, {1e-3, 1.0}, {1.0, 1.0}, {0.2, 5.0}}) {
    const flat_detail::LogRatioExcess excess(lo, hi);
    const flat_detail::SurelyInside inside(lo, hi, flat_detail::LogRatioExcess::kInsideMargin);
    std::size_t wrong = 0, said = 0, missed = 0, well_within = 0;
    for (double d : denominators())
      for (double n : numerators(lo, hi, d, rng)) {
        const bool in = inside(n, d), well = d > 1e-290 && d < 1e290 && n / d > lo * 1.01 && n / d < hi * 0.99;
        wrong += in && bits(excess(n / d)) != bits(0.0);
        said += in, missed += well && !in, well_within += well;
      }
    EXPECT_EQ(wrong, 0u) << "bounds " << lo << " " << hi;
    EXPECT_EQ(missed, 0u) << "bounds " << lo << " " << hi << ": " << well_within << " well within";
    if (lo < 0.5 * hi) EXPECT_GT(well_within, 10000u);
    if (lo == hi) EXPECT_EQ(said, 0u);  // an empty inside range: never
  }
}

// quotient_of_zero(n, d) is n / d to the bit for d > 0: +-0 keep their sign over subnormal,
// normal and infinite d; any other n is divided.
TEST(QuotientBounds, QuotientOfZeroIsTheQuotientsBits) {
  std::vector<double> ns = {0.0, -0.0, 1.0, -2.5, 1e-310, kInf, -kInf, std::numeric_limits<double>::quiet_NaN()};
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1e3, 1e3);
  for (int k = 0; k < 500; ++k) ns.push_back(u(rng));
  std::size_t compared = 0;
  for (double d : denominators()) {
    if (!(d > 0)) continue;
    for (double n : ns) {
      EXPECT_EQ(bits(flat_detail::quotient_of_zero(n, d)), bits(n / d)) << n << " / " << d;
      ++compared;
    }
  }
  EXPECT_TRUE(std::signbit(flat_detail::quotient_of_zero(-0.0, 2.0)));
  EXPECT_GT(compared, 100000u);
}

// The area energy's face gradients as written before the skipped divisions: excess of
// scale a2 / A3, dpen = lambda A3 2 x / a2 (issue 26 session 36's conformal_area_energy.h).
std::array<V2, 3> gradient_by_divisions(const flat_detail::ConformalAreaEnergy& e, const std::vector<V2>& pos,
                                        const test_shapes::SqueezedGrid& g, const std::vector<double>& area3, std::size_t i,
                                        double lo, double hi, double lambda, double scale) {
  const int f = e.faces()[i];
  const auto c = flat_detail::shifted_corners(g.s.t[std::size_t(f)], pos, g.emb.dy[std::size_t(f)]);
  const double a2 = 0.5 * flat_detail::area_energy_detail::cross2(c[1] - c[0], c[2] - c[0]);
  const double x = flat_detail::LogRatioExcess(lo, hi)(scale * a2 / area3[std::size_t(f)]);
  const double dpen = a2 > 0 ? lambda * area3[std::size_t(f)] * 2 * x / a2 : 0.0;
  std::array<V2, 3> grad = {V2::Zero(), V2::Zero(), V2::Zero()};
  for (int k = 0; k < 3; ++k) {
    const int a = (k + 1) % 3, b = (k + 2) % 3;
    const V2 ed = 2 * e.weights()[i][std::size_t(k)] * (c[std::size_t(a)] - c[std::size_t(b)]);
    grad[std::size_t(a)] += ed, grad[std::size_t(b)] -= ed;
    grad[std::size_t(k)] += dpen * 0.5 * V2(c[std::size_t(a)].y() - c[std::size_t(b)].y(), c[std::size_t(b)].x() - c[std::size_t(a)].x());
  }
  return grad;
}

// On a squeezed 48 x 24 grid moved by a fixed pattern (faces inside, near and far outside the bounds,
// some folded at the largest move), for wide and narrow bounds and two area scales: every face's
// gradient is the division formulas' to the bit.
TEST(QuotientBounds, AreaEnergyGradientsAreTheDivisionFormulasBits) {
  test_shapes::SqueezedGrid g(0.05, 2);
  std::vector<int> faces;
  std::vector<double> area3;
  for (std::size_t f = 0; f < g.s.t.size(); ++f) faces.push_back(int(f)), area3.push_back(flat_detail::face_area_3d(g.s, int(f)));
  std::size_t compared = 0;
  for (const auto& [lo, hi] : std::vector<std::pair<double, double>>{{0.4, 3.0}, {0.9, 1.1}})
    for (double scale : {1.0, 1.7})
      for (double amount : {0.0, 0.01, 0.3}) {
        const flat_detail::ConformalAreaEnergy e(g.s, g.emb, faces, area3, lo, hi, 10.0, scale);
        std::vector<V2> pos = g.emb.pos;
        for (std::size_t v = 0; v < pos.size(); ++v)
          if (!g.fixed[v]) pos[v] += amount * V2(std::sin(1.3 * double(v)), std::cos(0.7 * double(v)));
        std::vector<std::array<V2, 3>> got(faces.size());
        e.face_gradients(pos, got);
        for (std::size_t i = 0; i < faces.size(); ++i, ++compared) {
          const auto want = gradient_by_divisions(e, pos, g, area3, i, lo, hi, 10.0, scale);
          ASSERT_EQ(std::memcmp(got[i].data(), want.data(), sizeof want), 0) << i << " " << lo << " " << scale << " " << amount;
        }
      }
  EXPECT_GT(compared, 20000u);
}

}  // namespace
}  // namespace cf
