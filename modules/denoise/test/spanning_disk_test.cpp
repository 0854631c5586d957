// spanning_disk(): the disk of the sheet caps is a proper triangulated disk bounded by exactly the
// given ring, refined to the ring's edge length, with no chord between two ring vertices.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

#include "colonflat/denoise/spanning_disk.h"

namespace cf {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A saddle ring: a circle of radius r whose height oscillates twice around (z = a cos 2t).
std::vector<Vec3> saddle_ring(int n, double r, double a) {
  std::vector<Vec3> ring;
  for (int i = 0; i < n; ++i) {
    const double t = 2 * kPi * i / n;
    ring.push_back(Vec3(r * std::cos(t), r * std::sin(t), a * std::cos(2 * t)));
  }
  return ring;
}

// On a 120-vertex saddle ring: Euler characteristic 1 (a disk), every ring edge used once in the
// ring's direction and no other edge on the boundary, no edge between two ring vertices except
// ring edges, interior edges at most 4/3 of the ring edge after splitting (smoothing keeps them
// within 2x), every interior point inside the ring's bounding cylinder, unit normals.
TEST(DenoiseSpanningDisk, SaddleRingGivesRefinedDisk) {
  const int n = 120;
  const std::vector<Vec3> ring = saddle_ring(n, 10, 3);
  const double edge = (ring[1] - ring[0]).norm();
  const SpanningDisk d = spanning_disk(ring, edge);
  ASSERT_FALSE(d.triangles.empty());
  ASSERT_GT(d.points.size(), static_cast<std::size_t>(n) * 3) << "interior vertices expected";
  std::map<std::pair<int, int>, int> directed;
  std::set<std::pair<int, int>> edges;
  for (const auto& t : d.triangles)
    for (int e = 0; e < 3; ++e) {
      const int a = t[e], b = t[(e + 1) % 3];
      ++directed[{a, b}];
      edges.insert({std::min(a, b), std::max(a, b)});
    }
  const long chi = static_cast<long>(d.points.size()) - static_cast<long>(edges.size()) + static_cast<long>(d.triangles.size());
  EXPECT_EQ(chi, 1);
  int boundary = 0;
  for (const auto& [e, c] : directed) {
    EXPECT_EQ(c, 1);
    if (!directed.count({e.second, e.first})) {
      ++boundary;
      EXPECT_TRUE(e.first < n && e.second == (e.first + 1) % n) << e.first << " " << e.second;
    }
  }
  EXPECT_EQ(boundary, n);
  double longest = 0;
  for (const auto& [a, b] : edges) {
    if (a < n && b < n) EXPECT_TRUE(b == a + 1 || (a == 0 && b == n - 1)) << "chord " << a << " " << b;
    longest = std::max(longest, (d.points[a] - d.points[b]).norm());
  }
  EXPECT_LT(longest, 2 * edge);
  for (std::size_t j = n; j < d.points.size(); ++j) {
    const Vec3& p = d.points[j];
    EXPECT_LT(std::hypot(p[0], p[1]), 10 + 1e-9);
    EXPECT_LT(std::fabs(p[2]), 3 + 1e-9);
  }
  for (const auto& nrm : d.normals) EXPECT_NEAR(nrm.norm(), 1.0, 1e-9);
}

// Degenerate input gives nothing rather than a broken disk.
TEST(DenoiseSpanningDisk, TooFewPointsOrZeroEdgeGiveNothing) {
  EXPECT_TRUE(spanning_disk({Vec3(0, 0, 0), Vec3(1, 0, 0)}, 1.0).triangles.empty());
  EXPECT_TRUE(spanning_disk(saddle_ring(10, 1, 0), 0.0).triangles.empty());
}

}  // namespace
}  // namespace cf
