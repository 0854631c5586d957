// Restricted caps (surgery_caps.cpp): when the right ring's lightest clean cap leaves the left
// ring no clean cap, the two are made the other way round (Surgery::left_first). Checked on a
// pleated tube around a small closed box, with CGAL independently of the surgery's own count.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <thread>

#include "colonflat/core/topology.h"
#include "colonflat/testdata/synthetic.h"
#include "colonflat/denoise/surgery.h"
#include "self_intersections.h"

namespace cf {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A torus of radius kRadius whose cross-section is a rhombus of 4 vertices (half-diagonals kMajor
// radially, kMinor along z; vertices 0, 2 on the long diagonal, 1, 3 on the short one), in kSections
// sections one unit (an edge along the tube) apart, pleated: vertices 0 and 2 of every section
// kPleat units ahead along the tube, 1 and 3 kPleat behind. The meridian loop of section 0 is a
// skew quadrilateral, spanned by two caps without interior vertices: one over the short diagonal
// 1-3 (the lighter one, as kMinor < kMajor, whose middle lies kPleat behind the ring) and one over
// the long diagonal 0-2 (its middle kPleat ahead). Section i+1 lies ahead of section i: the loop's
// left side (faces left of 0 -> 1 -> 2 -> 3) is behind it, its right side ahead.
constexpr int kSections = 64;
constexpr double kRadius = kSections / (2 * kPi), kMajor = 1.2, kMinor = 0.6, kPleat = 0.8;

TriangleList pleated_tube() {
  const std::array<std::array<double, 3>, 4> cross = {{{kMajor, 0, kPleat}, {0, kMinor, -kPleat},
                                                      {-kMajor, 0, kPleat}, {0, -kMinor, -kPleat}}};  // r, z, ahead
  TriangleList t;
  for (int i = 0; i < kSections; ++i)
    for (const auto& c : cross) {
      const double u = (i + c[2]) / kRadius;
      t.points.push_back({(kRadius + c[0]) * std::cos(u), (kRadius + c[0]) * std::sin(u), c[1]});
    }
  for (int i = 0; i < kSections; ++i)
    for (int j = 0; j < 4; ++j) {
      const int a = i * 4 + j, b = ((i + 1) % kSections) * 4 + j, c = ((i + 1) % kSections) * 4 + (j + 1) % 4,
                d = i * 4 + (j + 1) % 4;
      t.triangles.push_back({a, b, c});
      t.triangles.push_back({a, c, d});
    }
  return t;
}

// A closed axis-aligned box (outward faces) around the tube's axis at section 0, from `behind` to
// `ahead` along the tube (y, at section 0) and kBox either side across it: well inside the rhombus.
constexpr double kBox = 0.15;
TriangleList box(double behind, double ahead) {
  TriangleList t;
  for (int c = 0; c < 8; ++c)
    t.points.push_back({kRadius + (c & 1 ? kBox : -kBox), c & 2 ? ahead : behind, c & 4 ? kBox : -kBox});
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    t.triangles.push_back({q[0], q[1], q[2]});
    t.triangles.push_back({q[0], q[2], q[3]});
  }
  return t;
}

struct Cut {
  Mesh mesh;
  SurgeryResult result;
};

// The tube with the box behind its loop, cut along the loop with a guard, without front caps
// (with `run_both`: SurgeryOptions::run_both, a helper thread).
Cut cut_loop(double behind, double ahead, const decltype(SurgeryOptions::run_both)& run_both = {}) {
  Cut c;
  c.mesh = synthetic::to_mesh(synthetic::disjoint_union(pleated_tube(), box(behind, ahead)));
  FaceGrid grid(c.mesh, 0.5);
  SurgeryOptions o;
  o.guard = &grid;
  o.front = false;  // front caps (interior vertices) span this loop too: the restricted step is the one tested
  o.run_both = run_both;
  const std::vector<Mesh::VertexHandle> loop = {Mesh::VertexHandle(0), Mesh::VertexHandle(1), Mesh::VertexHandle(2),
                                                Mesh::VertexHandle(3)};
  c.result = cut_and_cap(c.mesh, loop, o);
  return c;
}

// The input is what it claims: two closed, embedded, consistently oriented components (torus + box).
TEST(DenoiseSurgeryCaps, TubeAndBoxAreEmbedded) {
  const Mesh m = synthetic::to_mesh(synthetic::disjoint_union(pleated_tube(), box(-1.5, -0.78)));
  const auto t = analyze_topology(m);
  EXPECT_EQ(t.genus, 1);
  EXPECT_EQ(t.components.size(), 2u);
  EXPECT_TRUE(t.closed && t.manifold && t.consistently_oriented);
  EXPECT_EQ(testing::count_self_intersections(m), 0u);
}

// The box (0.78-1.5 behind the loop) lies where the left ring's light cap (over 1-3) passes in
// every placement (its middle 0.83-1.2 behind the loop: pleat 0.8 plus the left ring's pull) and
// the right ring's does not (its middle 0.08-0.72 behind); the right ring's light cap crosses the
// left ring's heavy one (over 0-2, its middle ahead of the former's, its corners 0, 2 behind).
// Made right ring first, the left ring has no clean cap in any of the 7 placements (the surgery
// falls back to concentric caps); made left ring first (its heavy cap, then the right ring's heavy
// cap, parallel to it) both are clean in the first: restricted caps, 0 pairs (CGAL), genus 0.
TEST(DenoiseSurgeryCaps, LeftRingFirstWhenTheRightCapBlocksIt) {
  Cut c = cut_loop(-1.5, -0.78);
  EXPECT_STREQ(c.result.caps, "restricted");
  EXPECT_EQ(c.result.placement, 0);  // the first placement already (right ring first: none of the 7)
  EXPECT_EQ(c.result.intersections, 0u);
  const auto t = analyze_topology(c.mesh);
  EXPECT_EQ(t.genus, 0);
  EXPECT_EQ(t.components.size(), 2u);  // the torus cut and capped (a sphere) and the box
  EXPECT_TRUE(t.closed && t.manifold && t.consistently_oriented);
  EXPECT_EQ(testing::count_self_intersections(c.mesh), 0u);
}

// Runs both jobs at once, the second on a thread of its own (what SurgeryOptions::run_both does).
void on_two_threads(const std::function<void()>& mine, const std::function<void()>& theirs) {
  std::thread helper(theirs);
  mine();
  helper.join();
}

// The left ring's cap that left_first() needs, triangulated on a helper thread beside the right
// ring's, is used (counted: 1, as the caps come from the first placement's left_first()) and
// gives the caps of one thread: the same vertices, points and faces, element by element.
TEST(DenoiseSurgeryCaps, LeftRingTriangulatedAheadGivesTheSameCaps) {
  const Cut one = cut_loop(-1.5, -0.78);
  const Cut two = cut_loop(-1.5, -0.78, on_two_threads);
  EXPECT_EQ(one.result.left_caps_ahead, 0);
  EXPECT_EQ(two.result.left_caps_ahead, 1);
  EXPECT_STREQ(two.result.caps, "restricted");
  EXPECT_EQ(two.result.placement, one.result.placement);
  ASSERT_EQ(two.mesh.n_vertices(), one.mesh.n_vertices());
  ASSERT_EQ(two.mesh.n_faces(), one.mesh.n_faces());
  for (auto v : one.mesh.vertices()) EXPECT_EQ(two.mesh.point(v), one.mesh.point(v)) << v.idx();
  for (auto f : one.mesh.faces()) {
    std::vector<int> a, b;
    for (auto v : one.mesh.fv_range(f)) a.push_back(v.idx());
    for (auto v : two.mesh.fv_range(f)) b.push_back(v.idx());
    EXPECT_EQ(a, b) << f.idx();
  }
}

}  // namespace
}  // namespace cf
