// Minimum-cut caps (surgery_mincut.cpp, free_space_cut.h): a loop whose disk has to pass a thin
// stepped gap between obstacles (the raw real-CT mask's "wall sieve", issue 26) is capped by a disk
// found in free space, where every disk fitted to the loop crosses the steps. Checked by CGAL
// independently of the surgery's own grid.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "colonflat/core/topology.h"
#include "colonflat/denoise/free_space_cut.h"
#include "colonflat/denoise/surgery.h"
#include "self_intersections.h"
#include "guarded_cut.h"
#include "swept_profile.h"

namespace cf {
namespace {

// A thick washer (rectangular profile r 4-8 mm, z -2..2, 0.25 mm spacing) swept in kSections;
// its loop round the hole at z = 0 spans a disk across the hole (radius 4). In the hole stand
// kColumns pairs of boxes, 1 mm wide along x with 0.1 mm slits, 4 mm deep along y: a lower box
// up to z = s_c - kGap / 2 and an upper one from s_c + kGap / 2, s_c zigzagging by kStep per
// column, so the loop's disk must pass a stepped gap of kGap mm between them (session 29's
// washer, "rawcap").
constexpr int kSections = 64;
constexpr int kColumns = 6;
constexpr double kGap = 1.0, kStep = 0.4;
constexpr int kLoopPoint = 16 + 16 + 16 + 8;  // profile: 16 bottom, 16 outer wall, 16 top, 16 inner wall (z = 2 down)

std::vector<std::array<double, 2>> washer_profile() {
  std::vector<std::array<double, 2>> p;  // (r, z), counter-clockwise
  for (int s = 0; s < 16; ++s) p.push_back({4.0 + 0.25 * s, -2.0});
  for (int s = 0; s < 16; ++s) p.push_back({8.0, -2.0 + 0.25 * s});
  for (int s = 0; s < 16; ++s) p.push_back({8.0 - 0.25 * s, 2.0});
  for (int s = 0; s < 16; ++s) p.push_back({4.0, 2.0 - 0.25 * s});
  return p;
}

double column_middle(int c) {
  static const double kZigzag[kColumns] = {0, 1, 2, 1, 0, -1};
  return kStep * kZigzag[c];
}

Mesh washer_with_stepped_gap() {
  TriangleList t = testing::swept_profile(washer_profile(), kSections, 0, 0.0);
  for (int c = 0; c < kColumns; ++c) {
    const double x0 = -3.0 + 1.0 * c + 0.05, x1 = x0 + 0.9, s = column_middle(c);
    t = synthetic::disjoint_union(t, testing::axis_box({x0, -2.0, -2.5}, {x1, 2.0, s - kGap / 2}));
    t = synthetic::disjoint_union(t, testing::axis_box({x0, -2.0, s + kGap / 2}, {x1, 2.0, 2.5}));
  }
  return synthetic::to_mesh(t);
}

std::vector<Mesh::VertexHandle> hole_loop() {
  return testing::swept_point_loop(kSections, static_cast<int>(washer_profile().size()), kLoopPoint);
}

using Cut = testing::GuardedCut;

// The hole loop cut with a guard, as in a loop's last cut (every cap kind), mincut caps on or off.
Cut cut_hole_loop(bool mincut, bool trial = false) {
  SurgeryOptions o;
  o.mincut = mincut;
  o.trial = trial;
  return testing::guarded_cut(washer_with_stepped_gap(), hole_loop(), o);
}

// The input is what it claims: a genus-1 washer and 12 boxes, closed, embedded, and the loop is
// the hole's circle at z = 0.
TEST(DenoiseMincutCaps, WasherAndStepsAreEmbedded) {
  const Mesh m = washer_with_stepped_gap();
  const auto t = analyze_topology(m);
  EXPECT_EQ(t.genus, 1);
  EXPECT_EQ(t.components.size(), 1u + 2 * kColumns);
  EXPECT_TRUE(t.closed && t.manifold && t.consistently_oriented);
  EXPECT_EQ(testing::count_self_intersections(m), 0u);
  const Vec3 p = m.point(hole_loop()[0]);
  EXPECT_NEAR(p[0], 4.0, 1e-9);
  EXPECT_NEAR(p[2], 0.0, 1e-9);
}

// Without mincut caps every cap kind crosses the steps: the surgery ends with concentric caps
// whose pairs it reports (and CGAL finds crossings too).
TEST(DenoiseMincutCaps, OtherCapsCrossTheSteps) {
  const Cut c = cut_hole_loop(false);
  EXPECT_STREQ(c.result.caps, "concentric");
  EXPECT_GT(c.result.intersections, 0u);
  EXPECT_GT(testing::count_self_intersections(c.mesh), 0u);
}

// With them the caps are mincut caps, clean by the surgery's own count and by CGAL, and the
// washer is cut to a sphere: genus 0, closed, manifold, consistently oriented.
TEST(DenoiseMincutCaps, MincutCapsPassTheSteppedGapCleanly) {
  const Cut c = cut_hole_loop(true);
  EXPECT_STREQ(c.result.caps, "mincut");
  EXPECT_EQ(c.result.intersections, 0u);
  EXPECT_EQ(testing::count_self_intersections(c.mesh), 0u);
  const auto t = analyze_topology(c.mesh);
  EXPECT_EQ(t.genus, 0);
  EXPECT_EQ(t.components.size(), 1u + 2 * kColumns);
  EXPECT_TRUE(t.closed && t.manifold && t.consistently_oriented);
}

// A trial (an alternative loop, kept only when clean) does not make them, so alternatives are
// judged as before.
TEST(DenoiseMincutCaps, TrialsDoNotMakeMincutCaps) {
  const Cut c = cut_hole_loop(true, true);
  EXPECT_STRNE(c.result.caps, "mincut");
  EXPECT_GT(c.result.intersections, 0u);
}

// Two square walls across the x axis, at x = 0.1 (side 1, the source's) and x = 1.9 (side 2).
std::vector<SidedTriangle> two_walls() {
  std::vector<SidedTriangle> tris;
  for (const auto& [x, side] : {std::pair{0.1, 1}, std::pair{1.9, 2}}) {
    tris.push_back({{Vec3(x, -1, -1), Vec3(x, 3, -1), Vec3(x, 3, 3)}, side});
    tris.push_back({{Vec3(x, -1, -1), Vec3(x, 3, 3), Vec3(x, -1, 3)}, side});
  }
  return tris;
}

// The 12 triangles of the axis box [lo, hi] added to `tris` on side `side`.
void add_box(std::vector<SidedTriangle>& tris, const std::array<double, 3>& lo, const std::array<double, 3>& hi, int side) {
  const TriangleList b = testing::axis_box(lo, hi);
  for (const auto& t : b.triangles) {
    std::array<Vec3, 3> p;
    for (int i = 0; i < 3; ++i) p[i] = Vec3(b.points[t[i]][0], b.points[t[i]][1], b.points[t[i]][2]);
    tris.push_back({p, side});
  }
}

// The minimum cut of a 2 mm cube at the origin, 8 x 8 x 8 cells of 0.25 mm, among `tris`.
std::vector<CutDisk> cut_two_mm_cube(const std::vector<SidedTriangle>& tris, FreeSpaceCutStats* st) {
  FreeSpaceBox box;
  box.lo = Vec3(0, 0, 0);
  box.cell = 0.25;
  box.n = {8, 8, 8};
  return free_space_cut(box, tris, st);
}

// The cut holds one disk of `squares` cell squares whose outer boundary has `boundary` lattice
// vertices, and its flow is `squares` (one unit per cell square cut).
void expect_one_disk(const std::vector<CutDisk>& disks, const FreeSpaceCutStats& st, int squares, std::size_t boundary) {
  EXPECT_EQ(st.flow, squares);
  ASSERT_EQ(disks.size(), 1u);
  EXPECT_EQ(disks[0].quads.size(), static_cast<std::size_t>(squares));
  EXPECT_EQ(disks[0].boundary.size(), boundary);
}

// Two parallel walls across a 2 mm box (x = 0.1: source side, x = 1.9: sink side): the minimum
// cut is one flat disk across the box, 8 x 8 cells of 0.25 mm, so the flow is 64 and the disk
// has 64 squares, 81 points, a boundary of 32 and normals along +x (towards the sink).
TEST(FreeSpaceCut, TwoWallsGiveAFlatDiskOfTheCrossSection) {
  std::vector<SidedTriangle> tris = two_walls();
  FreeSpaceCutStats st;
  const std::vector<CutDisk> disks = cut_two_mm_cube(tris, &st);
  ASSERT_NO_FATAL_FAILURE(expect_one_disk(disks, st, 64, 32));
  EXPECT_EQ(disks[0].points.size(), 81u);
  for (const auto& n : disks[0].normals) EXPECT_NEAR(n[0], 1.0, 1e-12);
}

// An obstacle (a box no flood reached, side 3) between those walls lies wholly on one side of the
// cut: the cut is a whole flat disk beside it (64 squares, flow 64), not the cheaper plane through
// it with a hole where it is (60 squares: an annulus, no disk).
TEST(FreeSpaceCut, AnObstacleLiesOnOneSideOfTheDisk) {
  std::vector<SidedTriangle> tris = two_walls();
  add_box(tris, {0.8, 0.8, 0.8}, {1.2, 1.2, 1.2}, 3);
  FreeSpaceCutStats st;
  const std::vector<CutDisk> disks = cut_two_mm_cube(tris, &st);
  ASSERT_NO_FATAL_FAILURE(expect_one_disk(disks, st, 64, 32));
}

// Two pegs between those walls, one standing on each (side 1 from the source wall up to x = 0.95,
// side 2 from the sink wall down to x = 1.05, both over y, z in [0.8, 1.2]), meet within 0.1 mm:
// less than a cell, so every cell of their four columns is blocked and the cut ends round them
// for free. The disk has a hole there (a rim of 8 lattice vertices round 2 x 2 cells): 60 squares,
// flow 60, outer boundary 32 (the raw CT mask's loop 91 has three such holes, session 31).
TEST(FreeSpaceCut, PegsMeetingWithinACellLeaveAHoleInTheDisk) {
  std::vector<SidedTriangle> tris = two_walls();
  add_box(tris, {0.1, 0.8, 0.8}, {0.95, 1.2, 1.2}, 1);
  add_box(tris, {1.05, 0.8, 0.8}, {1.9, 1.2, 1.2}, 2);
  FreeSpaceCutStats st;
  const std::vector<CutDisk> disks = cut_two_mm_cube(tris, &st);
  ASSERT_NO_FATAL_FAILURE(expect_one_disk(disks, st, 60, 32));
  ASSERT_EQ(disks[0].holes.size(), 1u);
  EXPECT_EQ(disks[0].holes[0].size(), 8u);
  for (int v : disks[0].holes[0]) {  // the rim runs round the pegs' square, y, z in {0.75, 1, 1.25}
    EXPECT_GT(std::fabs(disks[0].points[v][1] - 1.0) + std::fabs(disks[0].points[v][2] - 1.0), 0.2);
    EXPECT_LE(std::fabs(disks[0].points[v][1] - 1.0), 0.25 + 1e-9);
    EXPECT_LE(std::fabs(disks[0].points[v][2] - 1.0), 0.25 + 1e-9);
  }
}

// The triangle-box test against sampling: a triangle with a sampled point (fine barycentric grid)
// in the box meets it; a triangle whose bounding box holds the box but whose plane misses it does not.
TEST(FreeSpaceCut, TriangleBoxTestAgreesWithSampledPoints) {
  const Vec3 lo(0, 0, 0), hi(1, 1, 1);
  int checked = 0;
  for (int s = 0; s < 200; ++s) {
    std::array<Vec3, 3> t;
    for (int i = 0; i < 3; ++i)
      t[i] = Vec3(std::fmod(0.37 * (s * 3 + i) * 7.3, 3.0) - 1, std::fmod(0.53 * (s * 3 + i) * 5.1, 3.0) - 1,
                  std::fmod(0.71 * (s * 3 + i) * 3.7, 3.0) - 1);
    bool sampled = false;
    for (int a = 0; a <= 40 && !sampled; ++a)
      for (int b = 0; a + b <= 40 && !sampled; ++b) {
        const Vec3 p = (a * t[0] + b * t[1] + (40 - a - b) * t[2]) / 40.0;
        sampled = p[0] >= 0 && p[0] <= 1 && p[1] >= 0 && p[1] <= 1 && p[2] >= 0 && p[2] <= 1;
      }
    if (sampled) {
      EXPECT_TRUE(triangle_meets_box(t, lo, hi)) << s;
      ++checked;
    }
  }
  EXPECT_GT(checked, 20);
  EXPECT_FALSE(triangle_meets_box({Vec3(2, 2, 2), Vec3(3, 2, 2), Vec3(2, 3, 2.5)}, lo, hi));
  // Its bounding box holds the box, but its plane x + y + z = 3.5 passes beyond the corner (1, 1, 1).
  EXPECT_FALSE(triangle_meets_box({Vec3(3.5, 0, 0), Vec3(0, 3.5, 0), Vec3(0, 0, 3.5)}, lo, hi));
  EXPECT_TRUE(triangle_meets_box({Vec3(2.9, 0, 0), Vec3(0, 2.9, 0), Vec3(0, 0, 2.9)}, lo, hi));
}

}  // namespace
}  // namespace cf
