// Collar caps (surgery_collar.cpp): a loop lying on a wall in the wall's own tangent plane, whose
// caps without interior vertices lie in that plane and cross the wall's relief, is capped by
// caps lifted off the wall, within the gap to the sheet opposite; checked by CGAL independently
// of the surgery's own test.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "colonflat/core/synthetic.h"
#include "colonflat/core/threads.h"
#include "colonflat/core/topology.h"
#include "colonflat/denoise/homology.h"
#include "colonflat/denoise/surgery.h"
#include "self_intersections.h"
#include "guarded_cut.h"
#include "swept_profile.h"

namespace cf {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A flat ring-shaped plate (a washer: radii 2 to 6 mm, 0.3 mm thick) whose top face carries a
// concentric ripple of 1 mm wavelength, amplitude `ripple` x (r - 2) / 2 (so the trough at radius
// 4, top-face profile point kLoopPoint, is the deepest inside it), under a flat washer whose lower
// face lies `gap` mm above the ripple's reach (2 x ripple). The loop around the hole on the top face at
// radius 4 spans a disk in the top face's own plane: inside the loop that plane runs under the
// rippled face, through the plate, and out through the hole's rim.
constexpr int kLoopPoint = 63;  // profile: 40 bottom, 3 outer wall, 40 top (r = 6 ... 2.1), 3 rim
constexpr double kThickness = 0.3;

double top_face(double r, double ripple) { return kThickness / 2 - ripple * (r - 2) / 2 * std::cos(2 * kPi * (r - 4)); }

std::vector<std::array<double, 2>> washer_profile(double ripple) {
  std::vector<std::array<double, 2>> profile;  // (r, z), counter-clockwise
  const int steps = 40;                         // 0.1 mm
  for (int s = 0; s < steps; ++s) profile.push_back({2.0 + 0.1 * s, -kThickness / 2});         // bottom, outwards
  const double rise = top_face(6.0, ripple) + kThickness / 2;  // the outer wall up to the top face
  for (int s = 0; s < 3; ++s) profile.push_back({6.0, -kThickness / 2 + rise * s / 3});  // outer wall, up
  for (int s = steps; s > 0; --s) profile.push_back({2.0 + 0.1 * s, top_face(2.0 + 0.1 * s, ripple)});  // top, in
  for (int s = 0; s < 3; ++s) profile.push_back({2.0, top_face(2.0, ripple) - kThickness * s / 3});      // rim, down
  return profile;
}

Mesh rippled_washer_under_a_plate(double ripple, double gap, int nu) {
  const TriangleList lower = testing::swept_profile(washer_profile(ripple), nu, 0, 0.0);
  const TriangleList upper = synthetic::translated(testing::swept_profile(washer_profile(0), nu, 0, 0.0), 0, 0,
                                                   kThickness + 2 * ripple + gap);
  return synthetic::to_mesh(synthetic::disjoint_union(lower, upper));
}

std::vector<Mesh::VertexHandle> top_loop(int nu) {
  return testing::swept_point_loop(nu, static_cast<int>(washer_profile(0).size()), kLoopPoint);
}

using Cut = testing::GuardedCut;

// The steep ripple: a crest 0.175 mm above the loop half a millimetre inside it, higher than a
// collar may rise there (a third of the 0.45 mm between the loop and the plate).
constexpr double kGentleRipple = 0.02, kSteepRipple = 0.1;
double plate_gap(double ripple) { return ripple == kSteepRipple ? 0.15 : 0.3; }

Cut cut_top_loop(int nu, HomologyBasis* homology = nullptr, double ripple = kGentleRipple) {
  return testing::guarded_cut(rippled_washer_under_a_plate(ripple, plate_gap(ripple), nu), top_loop(nu), {}, homology);
}

// The test surface is what it claims: two embedded washers, genus 1 each, and the top loop at
// radius 4 lies in the deepest trough (the crests inside it are up to 0.035 mm higher).
TEST(DenoiseCollarCaps, TestSurfaceIsEmbeddedAndTheLoopLiesInATrough) {
  const Mesh m = rippled_washer_under_a_plate(0.02, 0.3, 96);
  const TopologyReport t = analyze_topology(m);
  EXPECT_EQ(t.genus, 2);
  EXPECT_EQ(t.components.size(), 2u);
  EXPECT_EQ(testing::count_self_intersections(m), 0u);
  const auto loop = top_loop(96);
  const Vec3 p = m.point(loop[0]);
  EXPECT_NEAR(std::hypot(p[0], p[1]), 4.0, 1e-9);
  EXPECT_NEAR(p[2], kThickness / 2 - 0.02, 1e-9);
}

// A 240-vertex loop on the rippled wall: every cap without interior vertices lies in the wall's
// plane and crosses the crests, so the caps are collar caps (no restricted triangulation, whose
// grid queries grow with the cube of the ring); the result is closed, manifold, genus 0 on that
// component, and CGAL finds no intersecting pair.
TEST(DenoiseCollarCaps, LongLoopOnARippledWallIsCappedCleanly) {
  const Cut c = cut_top_loop(240);
  EXPECT_STREQ(c.result.caps, "collar");
  EXPECT_EQ(c.result.intersections, 0u);
  const TopologyReport t = analyze_topology(c.mesh);
  EXPECT_EQ(t.genus, 1);  // the plate above keeps its handle
  EXPECT_TRUE(t.closed);
  EXPECT_TRUE(t.manifold);
  EXPECT_EQ(t.components.size(), 2u);
  EXPECT_EQ(testing::count_self_intersections(c.mesh), 0u);
}

// The lift stays within a third of the free distance: no collar vertex rises more than a third
// of the way from the ring to the plate above (0.36 mm; 1e-3 for the ring pull's own rise).
TEST(DenoiseCollarCaps, CollarStaysWithinAThirdOfTheGap) {
  const Cut c = cut_top_loop(96);
  ASSERT_STREQ(c.result.caps, "collar");
  const double plate = kThickness / 2 + 2 * 0.02 + 0.3;  // the plate's lower face
  const double ring = kThickness / 2 - 0.02;
  double highest = -1;
  for (std::size_t v = 0; v < c.mesh.n_vertices(); ++v) {
    const Vec3 p = c.mesh.point(Mesh::VertexHandle(static_cast<int>(v)));
    if (std::fabs(std::hypot(p[0], p[1]) - 4.0) < 0.05 && p[2] < plate - 0.01) highest = std::max(highest, p[2]);
  }
  EXPECT_GT(highest, ring + 0.04);  // lifted above the crests
  EXPECT_LE(highest - ring, (plate - ring) / 3 + 1e-3);
}

// The collar caps' new edges get homology classes that keep every face a cocycle: each face's
// edge classes sum to zero, except one closing face per cap, which sums to the cut loop's class
// (the class the exact method quotients out after the cut). Without this the searches after a
// collar cap would see wrong classes.
void expect_cap_edges_keep_faces_cocycles(double ripple, const char* caps) {
  HomologyBasis hb;
  const int nu = 96;
  Mesh before = rippled_washer_under_a_plate(ripple, plate_gap(ripple), nu);
  hb.build(before);
  std::vector<std::uint64_t> loop_class(hb.words(), 0);
  const auto loop = top_loop(nu);
  for (std::size_t i = 0; i < loop.size(); ++i)
    xor_into(loop_class.data(), hb.edge_class(before.edge_handle(before.find_halfedge(loop[i], loop[(i + 1) % nu]))),
             hb.words());
  ASSERT_FALSE(is_zero(loop_class.data(), hb.words()));
  const Cut c = cut_top_loop(nu, &hb, ripple);
  ASSERT_STREQ(c.result.caps, caps);
  int zero = 0, loop_sum = 0, other = 0;
  for (auto f : c.mesh.faces()) {
    std::vector<std::uint64_t> sum(hb.words(), 0);
    for (auto e : c.mesh.fe_range(f)) xor_into(sum.data(), hb.edge_class(e), hb.words());
    if (is_zero(sum.data(), hb.words())) ++zero;
    else if (sum == loop_class) ++loop_sum;
    else ++other;
  }
  EXPECT_EQ(other, 0);
  EXPECT_EQ(loop_sum, 2);
  EXPECT_GT(zero, 0);
}

TEST(DenoiseCollarCaps, CapEdgesKeepFacesCocycles) { expect_cap_edges_keep_faces_cocycles(kGentleRipple, "collar"); }

// The same caps for one and two threads, point by point and face by face.
void expect_same_caps_for_any_thread_count(double ripple) {
  const int before = thread_count();
  set_thread_count(1);
  const Cut one = cut_top_loop(96, nullptr, ripple);
  set_thread_count(2);
  const Cut two = cut_top_loop(96, nullptr, ripple);
  set_thread_count(before);
  ASSERT_EQ(one.mesh.n_vertices(), two.mesh.n_vertices());
  ASSERT_EQ(one.mesh.n_faces(), two.mesh.n_faces());
  for (auto v : one.mesh.vertices()) EXPECT_EQ(one.mesh.point(v), two.mesh.point(v));
  for (auto f : one.mesh.faces()) {
    auto a = one.mesh.cfv_iter(f);
    auto b = two.mesh.cfv_iter(f);
    for (int k = 0; k < 3; ++k, ++a, ++b) EXPECT_EQ(a->idx(), b->idx());
  }
}

TEST(DenoiseCollarCaps, SameCapsForAnyThreadCount) { expect_same_caps_for_any_thread_count(kGentleRipple); }

// The test surface with the steep ripple is what it claims: embedded, genus 1 per washer, the
// loop in the trough, and a crest inside the loop 0.175 mm above it.
TEST(DenoiseFrontCaps, SteepRippleSurfaceIsEmbeddedWithACrestInsideTheLoop) {
  const Mesh m = rippled_washer_under_a_plate(kSteepRipple, plate_gap(kSteepRipple), 96);
  EXPECT_EQ(analyze_topology(m).genus, 2);
  EXPECT_EQ(testing::count_self_intersections(m), 0u);
  EXPECT_NEAR(top_face(3.5, kSteepRipple) - m.point(top_loop(96)[0])[2], 0.175, 1e-9);
}

// A loop in the wall's own tangent plane with a crest inside it higher than any collar may rise:
// the flat caps, the collar caps and the caps of every placement cross the crest; a front cap
// (interior vertices steered off the wall) is clean in the first placement. The result is closed,
// manifold, genus 0 on that component, and CGAL finds no intersecting pair.
TEST(DenoiseFrontCaps, LoopUnderACrestIsCappedCleanlyInTheFirstPlacement) {
  for (int nu : {96}) {
    const Cut c = cut_top_loop(nu, nullptr, kSteepRipple);
    EXPECT_STREQ(c.result.caps, "front") << nu;
    EXPECT_EQ(c.result.placement, 0) << nu;
    EXPECT_EQ(c.result.intersections, 0u) << nu;
    const TopologyReport t = analyze_topology(c.mesh);
    EXPECT_EQ(t.genus, 1) << nu;  // the plate above keeps its handle
    EXPECT_TRUE(t.closed);
    EXPECT_TRUE(t.manifold);
    EXPECT_EQ(t.components.size(), 2u);
    EXPECT_EQ(testing::count_self_intersections(c.mesh), 0u) << nu;
  }
}

// The front caps' new edges keep every face a cocycle (one closing face per cap sums to the loop's class).
TEST(DenoiseFrontCaps, CapEdgesKeepFacesCocycles) { expect_cap_edges_keep_faces_cocycles(kSteepRipple, "front"); }

// The same front caps for one and two threads, point by point and face by face.
TEST(DenoiseFrontCaps, SameCapsForAnyThreadCount) { expect_same_caps_for_any_thread_count(kSteepRipple); }

}  // namespace
}  // namespace cf
