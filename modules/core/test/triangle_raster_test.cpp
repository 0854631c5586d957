// rasterise_triangles (core/triangle_raster.h): coverage and weights against brute force and
// analytic values, the tie rule, degenerate input and thread-count independence.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "colonflat/core/threads.h"
#include "colonflat/core/triangle_raster.h"

namespace cf {
namespace {

using Corners = std::array<std::array<double, 2>, 3>;

// A triangle fan around (cx, cy): n triangles whose outer corners lie on a circle of radius r.
std::vector<Corners> fan(double cx, double cy, double r, int n) {
  std::vector<Corners> t;
  for (int k = 0; k < n; ++k) {
    const double a0 = 2 * M_PI * k / n, a1 = 2 * M_PI * (k + 1) / n;
    t.push_back({{{cx, cy}, {cx + r * std::cos(a0), cy + r * std::sin(a0)}, {cx + r * std::cos(a1), cy + r * std::sin(a1)}}});
  }
  return t;
}

// n triangles with corners uniform in [0, size)^2 (either orientation, overlapping).
std::vector<Corners> random_triangles(unsigned seed, int n, double size) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, size);
  std::vector<Corners> t;
  for (int k = 0; k < n; ++k) t.push_back({{{u(rng), u(rng)}, {u(rng), u(rng)}, {u(rng), u(rng)}}});
  return t;
}

std::vector<RasterHit> raster(const RasterGrid& g, const std::vector<Corners>& t) {
  return rasterise_triangles(g, t.size(), [&](std::size_t i) { return t[i]; });
}

// Strictly inside (all three cross products of one sign, none near 0), by a formula of its own.
bool strictly_inside(const Corners& c, double x, double y) {
  int pos = 0, neg = 0;
  for (int k = 0; k < 3; ++k) {
    const auto &p = c[k], &q = c[(k + 1) % 3];
    const double s = (q[0] - p[0]) * (y - p[1]) - (q[1] - p[1]) * (x - p[0]);
    pos += s > 1e-9, neg += s < -1e-9;
  }
  return pos == 3 || neg == 3;
}

// Every pixel centre strictly inside some triangle of a 12-triangle fan is covered by that one,
// no centre outside the fan's polygon is covered, and the centres on the fan's shared spokes
// (the grid passes through the fan's centre) are covered too: no gap between neighbours.
TEST(TriangleRaster, CoverageMatchesBruteForceWithoutGapsOnSharedEdges) {
  const std::vector<Corners> t = fan(10, 10, 7.3, 12);
  const RasterGrid g{0.5, 0.5, 0.5, 40, 40};
  const std::vector<RasterHit> hits = raster(g, t);
  int inside = 0, on_spokes = 0;
  for (int j = 0; j < g.height; ++j)
    for (int i = 0; i < g.width; ++i) {
      const double x = g.x0 + i * g.spacing, y = g.y0 + j * g.spacing;
      const RasterHit& h = hits[std::size_t(j) * g.width + i];
      int owner = -1;
      for (std::size_t k = 0; k < t.size(); ++k)
        if (strictly_inside(t[k], x, y)) owner = int(k);
      const double rr = std::hypot(x - 10, y - 10);
      if (owner >= 0) {
        EXPECT_EQ(h.triangle, owner) << i << "," << j;
        ++inside;
      }
      if (rr > 7.3) EXPECT_LT(h.triangle, 0) << i << "," << j;
      if (owner < 0 && rr < 7.3 * std::cos(M_PI / 12) - 1e-6) {
        EXPECT_GE(h.triangle, 0) << i << "," << j;
        ++on_spokes;
      }
    }
  EXPECT_GT(inside, 500);
  EXPECT_GT(on_spokes, 0);  // the horizontal and vertical spokes pass through pixel centres
}

// The weights reproduce a linear function: sum_k w_k f(corner_k) = f(centre) to 1e-12, and each
// weight is within [0, 1] up to the edge slack, on random triangles of either orientation.
TEST(TriangleRaster, WeightsInterpolateLinearFunctionsExactly) {
  const std::vector<Corners> t = random_triangles(7, 30, 20);
  const RasterGrid g{0.25, 0.25, 0.5, 40, 40};
  const std::vector<RasterHit> hits = raster(g, t);
  auto f = [](double x, double y) { return 3 * x - 2 * y + 1; };
  int covered = 0;
  for (int j = 0; j < g.height; ++j)
    for (int i = 0; i < g.width; ++i) {
      const RasterHit& h = hits[std::size_t(j) * g.width + i];
      if (h.triangle < 0) continue;
      ++covered;
      const Corners& c = t[h.triangle];
      double s = 0;
      for (int k = 0; k < 3; ++k) {
        s += h.weight[k] * f(c[k][0], c[k][1]);
        EXPECT_GE(h.weight[k], -1e-12);
      }
      EXPECT_NEAR(s, f(g.x0 + i * g.spacing, g.y0 + j * g.spacing), 1e-9);
      EXPECT_NEAR(h.weight[0] + h.weight[1] + h.weight[2], 1.0, 1e-12);
    }
  EXPECT_GT(covered, 400);
}

// Where triangles overlap, the one with the highest index wins (a function of the order only).
TEST(TriangleRaster, OverlapGoesToTheLastTriangle) {
  const Corners big{{{0, 0}, {10, 0}, {0, 10}}}, small{{{1, 1}, {3, 1}, {1, 3}}};
  const RasterGrid g{0.5, 0.5, 1, 10, 10};
  EXPECT_EQ(raster(g, {big, small})[1 * 10 + 1].triangle, 1);  // centre (1.5, 1.5)
  EXPECT_EQ(raster(g, {small, big})[1 * 10 + 1].triangle, 1);
}

// A zero-area triangle covers nothing, an empty grid gives no hits, and a triangle outside the
// grid is clipped away.
TEST(TriangleRaster, DegenerateAndOutsideInputCoverNothing) {
  const RasterGrid g{0.5, 0.5, 1, 8, 8};
  const Corners line{{{0, 0}, {4, 4}, {8, 8}}}, far{{{100, 100}, {110, 100}, {100, 110}}};
  for (const RasterHit& h : raster(g, {line, far})) EXPECT_LT(h.triangle, 0);
  EXPECT_TRUE(raster(RasterGrid{0, 0, 1, 0, 5}, {fan(0, 0, 1, 3)}).empty());
}

// 1, 2 and 3 threads give the same hits, bit for bit, on overlapping random triangles.
TEST(TriangleRaster, SameHitsForAnyThreadCount) {
  const std::vector<Corners> t = random_triangles(3, 200, 30);
  const RasterGrid g{0.1, 0.2, 0.3, 100, 97};
  std::vector<std::vector<RasterHit>> runs;
  for (int n : {1, 2, 3}) {
    set_thread_count(n);
    runs.push_back(raster(g, t));
  }
  set_thread_count(0);
  for (std::size_t r = 1; r < runs.size(); ++r)
    for (std::size_t i = 0; i < runs[0].size(); ++i) {
      ASSERT_EQ(runs[r][i].triangle, runs[0][i].triangle);
      ASSERT_EQ(runs[r][i].weight, runs[0][i].weight);
    }
}

}  // namespace
}  // namespace cf
