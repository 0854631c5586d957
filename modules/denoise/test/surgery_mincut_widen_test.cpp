// Minimum-cut caps with wall widening (surgery_mincut_widen.cpp, issue 26 session 33 "rawden"):
// where two walls of the surface come within a cell inside a loop's disk (the raw real-CT mask's
// loop 91: air passages 0.21-0.38 mm thin), the free-space cut's disk has a hole there; the
// surgery moves the walls apart and cuts again. Checked by CGAL independently of the surgery's grid.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "colonflat/core/topology.h"
#include "colonflat/denoise/surgery.h"
#include "self_intersections.h"
#include "guarded_cut.h"
#include "swept_profile.h"

namespace cf {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kSections = 64;
constexpr double kFlat = kPi / 30, kSector = kPi / 12;  // the tongues: full within +-6 degrees of angle 0, none beyond 15
constexpr double kGap = 0.15;      // mm between the lower tongue's ridge and the upper tongue (less than a cell of 0.25 mm)
constexpr double kUnder = 0.75;    // mm: height of the upper tongue's underside (the loop at 0)
// Inner wall heights (r = 4), top to bottom; the loop runs at z = 0 (profile point kLoopPoint).
const std::vector<double> kInnerWall = {2.0, 1.5, 1.2, 1.0, 0.75, 0.0, -0.5, -0.55, -0.6, -0.65, -0.7, -0.8, -1.0, -1.2, -1.5};
constexpr int kLoopPoint = 16 + 16 + 16 + 5;

// 1 within kFlat of angle 0, a squared cosine down to 0 at kSector.
double tongue_weight(double u) {
  const double a = std::fabs(std::remainder(u, 2 * kPi));
  if (a >= kSector) return 0.0;
  return a <= kFlat ? 1.0 : std::pow(std::cos(0.5 * kPi * (a - kFlat) / (kSector - kFlat)), 2);
}

// The washer profile (r 4-8, z -2..2, counter-clockwise) at sweep angle u: within the sector two
// tongues 3.5 mm long grow from the inner wall towards the axis, the upper one with its underside
// flat at z = kUnder, the lower one with a ridge (r 1.7-2.3, its top r 1.95-2.05) that rises to kGap under it: a
// passage thinner than a cell inside the loop's disk, with room (1 mm) round it.
std::vector<std::array<double, 2>> tongue_profile(double u) {
  const double w = tongue_weight(u), ridge = kUnder - kGap;
  auto lerp = [w](double z, double r, double tip_z) { return std::array<double, 2>{4.0 + w * (r - 4.0), z + w * (tip_z - z)}; };
  std::vector<std::array<double, 2>> p;
  for (int s = 0; s < 16; ++s) p.push_back({4.0 + 0.25 * s, -2.0});
  for (int s = 0; s < 16; ++s) p.push_back({8.0, -2.0 + 0.25 * s});
  for (int s = 0; s < 16; ++s) p.push_back({8.0 - 0.25 * s, 2.0});
  for (double z : kInnerWall) {
    if (z == 1.2) p.push_back(lerp(z, 0.5, kUnder + 0.6));  // upper tongue: tip's top
    else if (z == 1.0) p.push_back(lerp(z, 0.5, kUnder));   // tip's underside (flat to the wall at kUnder)
    else if (z == -0.55) p.push_back(lerp(z, 2.3, -0.3));   // lower tongue: a ridge rising to kGap under the upper one
    else if (z == -0.6) p.push_back(lerp(z, 2.05, ridge));
    else if (z == -0.65) p.push_back(lerp(z, 1.95, ridge));
    else if (z == -0.7) p.push_back(lerp(z, 1.7, -0.3));
    else if (z == -0.8) p.push_back(lerp(z, 0.5, -0.5));    // tip's top
    else if (z == -1.0) p.push_back(lerp(z, 0.5, -0.9));    // tip's underside
    else p.push_back({4.0, z});
  }
  return p;
}

// The washer with tongues: section i holds the profile at angle 2 pi i / kSections (vertices
// [i * n, (i + 1) * n)).
Mesh tongued_washer() {
  TriangleList t;
  const int n = static_cast<int>(tongue_profile(0).size());
  for (int i = 0; i < kSections; ++i) {
    const double u = 2 * kPi * i / kSections;
    for (const auto& p : tongue_profile(u)) t.points.push_back({p[0] * std::cos(u), p[0] * std::sin(u), p[1]});
  }
  for (int i = 0; i < kSections; ++i)
    for (int j = 0; j < n; ++j) {
      const int a = i * n + j, b = ((i + 1) % kSections) * n + j, c = ((i + 1) % kSections) * n + (j + 1) % n, d = i * n + (j + 1) % n;
      t.triangles.push_back({a, b, c});
      t.triangles.push_back({a, c, d});
    }
  return synthetic::to_mesh(t);
}

std::vector<Mesh::VertexHandle> hole_loop() {
  return testing::swept_point_loop(kSections, static_cast<int>(tongue_profile(0).size()), kLoopPoint);
}

using Cut = testing::GuardedCut;

// The hole loop cut as in a loop's last cut after its triangulated caps failed: minimum-cut caps,
// then concentric ones; walls widened by up to `widen` cells (0: never).
Cut cut_hole_loop(double widen) {
  SurgeryOptions o;
  o.mincut = true;
  o.triangulated = false;
  o.mincut_widen = widen;
  return testing::guarded_cut(tongued_washer(), hole_loop(), o);
}

// The input is what it claims: a closed, embedded genus-1 surface whose loop is the hole's circle
// r = 4 at z = 0, and the ridge's top (r 1.95-2.05 at angle 0) is kGap under the upper tongue.
TEST(DenoiseMincutWiden, TonguedWasherIsEmbedded) {
  const Mesh m = tongued_washer();
  const auto t = analyze_topology(m);
  EXPECT_EQ(t.genus, 1);
  EXPECT_TRUE(t.closed && t.manifold && t.consistently_oriented);
  EXPECT_EQ(testing::count_self_intersections(m), 0u);
  const Vec3 p = m.point(hole_loop()[0]);
  EXPECT_NEAR(p[0], 4.0, 1e-9);
  EXPECT_NEAR(p[2], 0.0, 1e-9);
  const auto tip = tongue_profile(0);
  EXPECT_NEAR(tip[16 * 3 + 3][1] - tip[16 * 3 + 8][1], kGap, 1e-9);
  EXPECT_NEAR(tip[16 * 3 + 8][0], 2.05, 1e-9);
}

// Without widening the cut's disk has a hole over the ridge, which no fill threads: the
// minimum-cut caps fail and the concentric caps cross the tongues.
TEST(DenoiseMincutWiden, WithoutWideningTheCapsCrossTheTongues) {
  const Cut c = cut_hole_loop(0.0);
  EXPECT_STREQ(c.result.caps, "concentric");
  EXPECT_GT(c.result.intersections, 0u);
  EXPECT_EQ(c.result.widened, 0.0);
  EXPECT_GT(testing::count_self_intersections(c.mesh), 0u);
}

// With widening the ridge and the upper tongue move apart (1.5 cells = 0.375 mm a round, at most 3
// rounds), the disk passes between them and the caps are clean by the surgery's count and by CGAL;
// the washer becomes a sphere, and the largest move of an input vertex is the one reported.
TEST(DenoiseMincutWiden, WideningTheRidgeGivesCleanMincutCaps) {
  const Cut c = cut_hole_loop(1.5);
  EXPECT_STREQ(c.result.caps, "mincut");
  EXPECT_EQ(c.result.intersections, 0u);
  EXPECT_GT(c.result.widened, 0.0);
  EXPECT_LE(c.result.widened, 3 * 1.5 * 0.25 + 1e-9);
  EXPECT_EQ(testing::count_self_intersections(c.mesh), 0u);
  const auto t = analyze_topology(c.mesh);
  EXPECT_EQ(t.genus, 0);
  EXPECT_TRUE(t.closed && t.manifold && t.consistently_oriented);
  const Mesh before = tongued_washer();
  const auto loop = hole_loop();
  double largest = 0;  // the moves as the result reports them (the loop's vertices are the right ring's)
  for (auto v : before.vertices())
    if (std::find(loop.begin(), loop.end(), v) == loop.end())
      largest = std::max(largest, (c.mesh.point(v) - before.point(v)).norm());
  EXPECT_NEAR(largest, c.result.widened, 1e-9);
}

}  // namespace
}  // namespace cf
