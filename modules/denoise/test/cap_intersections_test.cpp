// Caps on thin, bent bands (the cross-sections that defeated centroid-based caps on the shared
// cup and heptoroid meshes) and at the creases of marching-cubes surfaces: surgery with a guard
// introduces no self-intersection, checked by CGAL independently of the surgery's own test.
#include <gtest/gtest.h>

#include <cmath>

#include "bench_meshes.h"
#include "colonflat/core/synthetic.h"
#include "colonflat/denoise/denoise.h"
#include "colonflat/core/threads.h"
#include "colonflat/core/topology.h"
#include "colonflat/denoise/surgery.h"
#include "self_intersections.h"
#include "swept_profile.h"

namespace cf {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A closed band: the profile (a thin chevron of `side` vertices per wall side, arm length 1,
// wall `thickness`) swept around the z axis at radius R with nu sections, turning `twist` half
// turns on the way round (even: the V must come back upright to close up).
// Genus 1; section i holds vertices [i * n, (i + 1) * n).
Mesh chevron_band(double thickness, int side, int nu, int twist, double R = 4) {
  std::vector<std::array<double, 2>> profile;  // (radial, z), counter-clockwise
  const double h = thickness / 2;
  for (int s = 0; s < side; ++s) {  // lower wall side, left to right
    const double x = -1 + 2.0 * s / (side - 1);
    profile.push_back({x * 0.7, std::fabs(x) * 0.7 - h * std::sqrt(2.0)});
  }
  for (int s = side - 1; s >= 0; --s) {  // upper wall side, right to left
    const double x = -1 + 2.0 * s / (side - 1);
    profile.push_back({x * 0.7, std::fabs(x) * 0.7 + h * std::sqrt(2.0)});
  }
  return synthetic::to_mesh(testing::swept_profile(profile, nu, twist, R));
}

struct Band {
  double thickness;
  int twist;
  int side = 20;  // vertices per wall side: loops of 2 x side vertices
};
void PrintTo(const Band& b, std::ostream* os) {
  *os << "thickness " << b.thickness << ", " << b.twist << " half turns, loop of " << 2 * b.side;
}

class DenoiseCapIntersections : public ::testing::TestWithParam<Band> {};

// Cutting a thin chevron band across (loops of 40 vertices like heptoroid's, and of 300) leaves a
// closed, manifold, genus-0 surface with no self-intersection, and the guard reports none.
TEST_P(DenoiseCapIntersections, ChevronBandCutCleanly) {
  const Band b = GetParam();
  Mesh m = chevron_band(b.thickness, b.side, 48, b.twist);
  ASSERT_EQ(analyze_topology(m).genus, 1);
  ASSERT_EQ(testing::count_self_intersections(m), 0u) << "the band itself must be embedded";
  const int n = 2 * b.side;
  std::vector<Mesh::VertexHandle> loop;
  for (int j = 0; j < n; ++j) loop.push_back(Mesh::VertexHandle(7 * n + j));
  FaceGrid grid(m, 2 * testing::mean_edge(m));
  SurgeryOptions o;
  o.guard = &grid;
  const SurgeryResult r = cut_and_cap(m, loop, o);
  const TopologyReport t = analyze_topology(m);
  EXPECT_EQ(t.genus, 0);
  EXPECT_TRUE(t.closed);
  EXPECT_TRUE(t.manifold);
  EXPECT_EQ(t.components.size(), 1u);
  EXPECT_EQ(r.intersections, 0u);
  EXPECT_EQ(testing::count_self_intersections(m), 0u);
}

INSTANTIATE_TEST_SUITE_P(Bands, DenoiseCapIntersections,
                         ::testing::Values(Band{0.05, 0}, Band{0.05, 2}, Band{0.02, 2}, Band{0.1, 4}, Band{0.02, 2, 150}),
                         [](const ::testing::TestParamInfo<Band>& i) {
                           return "t" + std::to_string(static_cast<int>(i.param.thickness * 1000)) + "um_twist" +
                                  std::to_string(i.param.twist) + "_loop" + std::to_string(2 * i.param.side);
                         });

// Flying-edges surfaces of a sphere with half-sunk tori (12 handles, ~20K faces): the tunnel loops
// at the torus-sphere junctions run along creases where pulling a ring along the averaged tangent
// plane folds the faces around it (seeds 3, 11 and 12 did before rings could move along their
// side's edges). Denoising leaves no new self-intersection, and reports none.
TEST(DenoiseCapIntersections, MarchingCubesJunctionsCutCleanly) {
  for (unsigned seed : {3u, 11u, 12u}) {
    const Mesh m = bench::sphere_with_handles(25, 12, 0.6, seed);
    const std::size_t before = testing::count_self_intersections(m);
    const DenoiseResult r = denoise(m, DenoiseOptions{});
    EXPECT_EQ(*r.after.genus, 0) << "seed " << seed;
    EXPECT_EQ(testing::count_self_intersections(r.mesh), before) << "seed " << seed;
    EXPECT_EQ(r.report["totals"]["cap_intersections"].get<std::size_t>(), 0u) << "seed " << seed;
  }
}

// Both components (torus and blocker) have genus 0; closed, manifold, oriented, and CGAL finds
// no intersecting pair.
void expect_two_clean_spheres(const Mesh& mesh) {
  const TopologyReport t = analyze_topology(mesh);
  ASSERT_EQ(t.components.size(), 2u);
  for (const auto& c : t.components) EXPECT_EQ(c.genus, 0);
  EXPECT_TRUE(t.closed && t.manifold && t.consistently_oriented);
  EXPECT_EQ(testing::count_self_intersections(mesh), 0u);
}

// One loop, the blocked torus' thinnest meridian itself (no replacement), capped with 0 pairs.
void expect_thinnest_meridian_capped_cleanly(const DenoiseResult& r) {
  ASSERT_EQ(r.loops.size(), 1u);
  EXPECT_NEAR(r.loops[0].length, 2 * kPi * 0.85, 0.05 * 2 * kPi * 0.85);  // the thinnest meridian itself
  EXPECT_EQ(r.loops[0].cap_intersections, 0u);
  EXPECT_EQ(r.report["search"]["loops_replaced_for_clean_caps"], 0);
  expect_two_clean_spheres(r.mesh);
}

// The blocked torus with `kind` (checked embedded first) denoised with front caps off.
DenoiseResult denoise_without_front_caps(bench::Blocker kind) {
  const Mesh m = bench::blocked_torus(kind);
  EXPECT_EQ(testing::count_self_intersections(m), 0u) << "the input must be embedded";
  DenoiseOptions o;
  o.front_caps = false;
  return denoise(m, o);
}

// Front caps bend around the tip of a rod inside the tube: the thinnest meridian, whose flat,
// collar and restricted caps all cross the rod, is cut and capped cleanly in the first placement
// (no replacement loop), 0 intersecting pairs (CGAL), genus 0 per component.
TEST(DenoiseCapIntersections, FrontCapsGoAroundABlockingRod) {
  const Mesh m = bench::blocked_torus(bench::Blocker::kRod);
  const DenoiseResult r = denoise(m, DenoiseOptions{});
  expect_thinnest_meridian_capped_cleanly(r);
}

// When every placement of the shortest loop's caps crosses the surface (a rod inside the tube
// pierces every cap of the thinnest meridian; front caps off, which would bend around its tip),
// the surgery is undone and another loop of the same class away from the rod is cut instead: 0
// intersecting pairs (CGAL), genus 0 per component, and the report names the loop it replaced.
TEST(DenoiseCapIntersections, BlockedLoopIsReplacedBySameClassLoop) {
  const DenoiseResult r = denoise_without_front_caps(bench::Blocker::kRod);
  ASSERT_EQ(r.loops.size(), 1u);
  const LoopRecord& loop = r.loops[0];
  EXPECT_EQ(loop.cap_intersections, 0u);
  EXPECT_GT(loop.replaced_intersections, 0u) << "the first placement must have been blocked";
  const double thinnest = 2 * kPi * 0.85;  // circumference of the blocked meridian
  EXPECT_NEAR(loop.replaced_length, thinnest, 0.05 * thinnest);
  EXPECT_GT(loop.length, loop.replaced_length);
  EXPECT_LT(loop.length, 2 * kPi * 1.15);  // still a meridian (same class), not the longitude
  EXPECT_EQ(r.report["search"]["loops_replaced_for_clean_caps"], 1);
  EXPECT_EQ(r.report["totals"]["cap_intersections"].get<std::size_t>(), 0u);
  expect_two_clean_spheres(r.mesh);
}

// The blocked torus's thinnest meridian (the exact method's first loop, cut without the cap
// check) cut alone on a fresh copy, front caps off, with the given concentric placement rule
// (and without the triangulated caps when `triangulated` is off).
SurgeryResult cut_thinnest_meridian(bench::Blocker kind, bool trial, bool probe, Mesh* out, bool triangulated = true) {
  const Mesh m = bench::blocked_torus(kind);
  DenoiseOptions unchecked;
  unchecked.check_caps = false;
  const DenoiseResult first = denoise(m, unchecked);
  std::vector<Mesh::VertexHandle> loop;
  for (int id : first.loops.at(0).vertex_ids) loop.push_back(Mesh::VertexHandle(id));
  *out = m;
  FaceGrid grid(*out, 3 * testing::mean_edge(*out));
  SurgeryOptions o;
  o.guard = &grid;
  o.front = false;
  o.trial = trial;
  o.probe_concentric = probe;
  o.triangulated = triangulated;
  return cut_and_cap(*out, loop, o);
}

// a and b hold the same points and the same faces (vertex ids in order).
void expect_same_mesh(const Mesh& a, const Mesh& b) {
  ASSERT_EQ(a.n_vertices(), b.n_vertices());
  ASSERT_EQ(a.n_faces(), b.n_faces());
  for (auto v : a.vertices()) EXPECT_EQ(a.point(v), b.point(v)) << v.idx();
  for (auto f : a.faces()) {
    auto ia = a.cfv_iter(f);
    auto ib = b.cfv_iter(f);
    for (int i = 0; i < 3; ++i, ++ia, ++ib) EXPECT_EQ(ia->idx(), ib->idx()) << f.idx();
  }
}

// A loop's first cut only probes the concentric placements for a clean one (each count stops at
// its first pair): where one is clean (the core blob) it gives the full search's caps, point for
// point; where none is (a rod through every meridian's caps) the caps stay in the first
// placement and report its pairs, which the full search would have lowered. A trial leaves the
// same caps there but counts only up to its first pair (it is kept only when clean).
TEST(DenoiseCapIntersections, ProbedConcentricPlacementsOnlyLookForACleanOne) {
  Mesh full_mesh, probe_mesh, trial_mesh;
  const SurgeryResult full = cut_thinnest_meridian(bench::Blocker::kCoreBlob, false, false, &full_mesh);
  const SurgeryResult probe = cut_thinnest_meridian(bench::Blocker::kCoreBlob, false, true, &probe_mesh);
  ASSERT_EQ(full.intersections, 0u);
  EXPECT_EQ(probe.intersections, 0u);
  ASSERT_EQ(probe_mesh.n_vertices(), full_mesh.n_vertices());
  for (auto v : full_mesh.vertices()) EXPECT_EQ(probe_mesh.point(v), full_mesh.point(v)) << v.idx();
  const SurgeryResult rod_full = cut_thinnest_meridian(bench::Blocker::kRod, false, false, &full_mesh);
  const SurgeryResult rod_probe = cut_thinnest_meridian(bench::Blocker::kRod, false, true, &probe_mesh);
  const SurgeryResult rod_trial = cut_thinnest_meridian(bench::Blocker::kRod, true, false, &trial_mesh);
  EXPECT_GT(rod_probe.intersections, 1u);
  EXPECT_EQ(rod_trial.intersections, 1u) << "a trial's count stops at its first pair";
  expect_same_mesh(trial_mesh, probe_mesh);
  EXPECT_LT(rod_full.intersections, rod_probe.intersections) << "the full search must lower the first placement's pairs";
}

// A loop whose triangulated caps all fail (the rod through every meridian's caps) gets the same
// concentric caps, vertex for vertex and face for face, when the triangulated steps are skipped
// (CapAttempt::kAgain: the fallback's last cut of a loop whose first cut already failed them).
TEST(DenoiseCapIntersections, SkippingFailedTriangulatedCapsGivesTheSameConcentricCaps) {
  Mesh full_mesh, again_mesh;
  const SurgeryResult full = cut_thinnest_meridian(bench::Blocker::kRod, false, false, &full_mesh);
  const SurgeryResult again = cut_thinnest_meridian(bench::Blocker::kRod, false, false, &again_mesh, false);
  ASSERT_STREQ(full.caps, "concentric");
  ASSERT_GT(full.intersections, 0u);
  EXPECT_STREQ(again.caps, "concentric");
  EXPECT_EQ(again.intersections, full.intersections);
  expect_same_mesh(again_mesh, full_mesh);
}

// A blob at the tube core (+-0.6 mm along the tube, 0.6 mm across) is crossed by every flat,
// collar and restricted cap of the thinnest meridian and by concentric caps bulged by up to one
// ring edge (0.33 mm); a concentric cap bulged by a fraction of the loop's radius passes over it,
// so with front caps off the meridian itself is capped cleanly (CGAL: 0 pairs), not replaced by a
// longer loop (on a84c05a it was replaced).
TEST(DenoiseCapIntersections, DomedConcentricCapsPassOverACoreBlob) {
  const DenoiseResult r = denoise_without_front_caps(bench::Blocker::kCoreBlob);
  expect_thinnest_meridian_capped_cleanly(r);
}

// With a ring along the whole tube core no meridian can be capped cleanly (the ring links every
// one): the handle is removed through its other loop, one crossing the meridian (the longitude,
// whose disk spans the torus' hole), with 0 intersecting pairs (CGAL), genus 0 per component,
// and the report names the meridian it replaced. Before, the meridian was cut across the ring.
TEST(DenoiseCapIntersections, UncappableLoopIsReplacedByTheHandlesOtherLoop) {
  const Mesh m = bench::blocked_torus(bench::Blocker::kCoreRing);
  ASSERT_EQ(testing::count_self_intersections(m), 0u) << "the input must be embedded";
  const DenoiseResult r = denoise(m, DenoiseOptions{});
  ASSERT_EQ(r.loops.size(), 2u);  // the core ring's own meridian, then the torus' handle
  const LoopRecord& loop = r.loops[1];
  EXPECT_EQ(loop.cap_intersections, 0u);
  EXPECT_GT(loop.replaced_intersections, 0u) << "the meridian's caps must have been blocked";
  EXPECT_NEAR(loop.replaced_length, 2 * kPi * 0.85, 0.05 * 2 * kPi * 0.85);  // the thinnest meridian
  EXPECT_GT(loop.length, 2 * kPi * 2.8);  // around the hole: a longitude (inner radius 2.85-3.15)
  EXPECT_LT(loop.length, 2 * kPi * 3.2);
  EXPECT_EQ(r.report["search"]["loops_replaced_by_crossing_loop"], 1);
  EXPECT_EQ(r.report["totals"]["cap_intersections"].get<std::size_t>(), 0u);
  expect_two_clean_spheres(r.mesh);
}

// A plug filling the tube at the thinnest meridian and a rod along the rest of its core: the
// thinnest meridian (every disk of which crosses the plug, as a rim's disks cross the wall
// beside it), the same-class loops a quarter of a meridian away (the rod) and the loops crossing
// it (the link ring) have no clean caps; the meridian two or three sections off the plug has.
// It is found (a tube of a few edges around the failing loop) and cut: 0 intersecting pairs
// (CGAL), genus 0 per component. On 8e52242 the thinnest meridian was cut across the plug.
TEST(DenoiseCapIntersections, LoopBesideAWallIsReplacedByOneAFewEdgesOff) {
  const Mesh m = bench::blocked_torus(bench::Blocker::kWaistPlugAndRod);
  ASSERT_EQ(testing::count_self_intersections(m), 0u) << "the input must be embedded";
  DenoiseOptions o;
  o.front_caps = false;  // they bend round the rod's tip (FrontCapsGoAroundABlockingRod)
  const DenoiseResult r = denoise(m, o);
  const LoopRecord& loop = r.loops.back();  // the torus' handle (the link ring's meridian first)
  EXPECT_GT(loop.replaced_intersections, 0u) << "the thinnest meridian's caps must have been blocked";
  EXPECT_NEAR(loop.replaced_length, 2 * kPi * 0.85, 0.05 * 2 * kPi * 0.85);
  EXPECT_LT(loop.length, 2 * kPi * 0.9);  // a meridian a few sections off (radius 0.86-0.87)
  EXPECT_EQ(r.report["search"]["loops_replaced_for_clean_caps"], 1);
  EXPECT_EQ(r.report["totals"]["cap_intersections"].get<std::size_t>(), 0u);
  const TopologyReport t = analyze_topology(r.mesh);
  for (const auto& c : t.components) EXPECT_EQ(c.genus, 0);
  EXPECT_TRUE(t.closed && t.manifold && t.consistently_oriented);
  EXPECT_EQ(testing::count_self_intersections(r.mesh), 0u);
}

// With a second ring through the hole as well, every loop that removes the torus' handle is
// linked with a ring, so no clean cap exists: the intersecting pairs are reported (never hidden)
// and --strict turns them into an error.
TEST(DenoiseCapIntersections, UncappableLoopIsReportedAndStrictFails) {
  const Mesh m = bench::blocked_torus(bench::Blocker::kCoreAndLinkRings);
  ASSERT_EQ(testing::count_self_intersections(m), 0u) << "the input must be embedded";
  const DenoiseResult r = denoise(m, DenoiseOptions{});
  EXPECT_GT(r.report["totals"]["cap_intersections"].get<std::size_t>(), 0u);
  EXPECT_EQ(r.report["totals"]["loops_with_cap_intersections"].get<std::size_t>(), 1u);
  DenoiseOptions strict;
  strict.strict = true;
  EXPECT_THROW(denoise(m, strict), Error);
}

// A torus (R 4 mm, tube 1 mm, 48 sections of 16 points) with a waist at section 7 (radius 0.85:
// the shortest loop is that meridian, vertices [7 * 16, 8 * 16)), and a thin spike (a tetrahedron,
// its own component) piercing the wall between sections 7 and 8 from outside, its tip 0.04 mm
// inside: the input crosses itself at a face around the meridian, as the folds of a mask grown
// until its walls fuse do at their tiny tunnels (issue 26: 946 such pairs on the real mask grown
// by one voxel), away from any disk of the meridian. Sets *first_new_face to the face count.
Mesh waisted_torus_with_piercing_spike(int* first_new_face) {
  constexpr int kN = 16, kNu = 48;
  std::vector<std::array<double, 2>> circle;
  for (int j = 0; j < kN; ++j) circle.push_back({std::cos(2 * kPi * j / kN), std::sin(2 * kPi * j / kN)});
  TriangleList t = testing::swept_profile(circle, kNu, 0, 4);
  for (int i = 0; i < kNu; ++i) {
    const double d = std::min(std::abs(i - 7), kNu - std::abs(i - 7)), s = 1 - 0.15 * std::exp(-d * d / 4);
    const Vec3 c(4 * std::cos(2 * kPi * i / kNu), 4 * std::sin(2 * kPi * i / kNu), 0);
    for (int j = 0; j < kN; ++j) {
      auto& p = t.points[i * kN + j];
      for (int a = 0; a < 3; ++a) p[a] = c[a] + s * (p[a] - c[a]);
    }
  }
  auto at = [&](int i, int j) { const auto& p = t.points[i * kN + j]; return Vec3(p[0], p[1], p[2]); };
  const Vec3 wall = 0.2 * (at(7, 4) + at(7, 5)) + 0.3 * (at(8, 4) + at(8, 5));  // 0.6 of the way to section 8
  const Vec3 axis = 0.5 * (at(7, 4) + at(8, 5) - at(7, 12) - at(8, 13));      // across the tube: outward
  const Vec3 out = axis / axis.norm(), side = OpenMesh::cross(out, Vec3(0, 0, 1)).normalized(),
             up = OpenMesh::cross(out, side);
  const Vec3 tip = wall - 0.04 * out, base = wall + 0.3 * out;
  std::vector<Vec3> spike{tip};
  for (int k = 0; k < 3; ++k)
    spike.push_back(base + 0.08 * (std::cos(2 * kPi * k / 3) * side + std::sin(2 * kPi * k / 3) * up));
  const Vec3 centre = 0.25 * (spike[0] + spike[1] + spike[2] + spike[3]);
  const int o = static_cast<int>(t.points.size());
  for (const Vec3& p : spike) t.points.push_back({p[0], p[1], p[2]});
  for (std::array<int, 3> f : {std::array<int, 3>{0, 1, 2}, {0, 2, 3}, {0, 3, 1}, {1, 3, 2}}) {
    const Vec3 n = OpenMesh::cross(spike[f[1]] - spike[f[0]], spike[f[2]] - spike[f[0]]);
    if (OpenMesh::dot(n, spike[f[0]] - centre) < 0) std::swap(f[1], f[2]);  // outward
    t.triangles.push_back({o + f[0], o + f[1], o + f[2]});
  }
  Mesh m = synthetic::to_mesh(t);
  *first_new_face = static_cast<int>(m.n_faces());
  return m;
}

// The cap checks count only crossings the surgery makes (issue 26, session 28): with the input
// crossing itself at a face around the shortest loop (a spike through the wall next to it), that
// loop itself is cut and capped with triangulated caps and 0 pairs, not replaced (before, every
// placement failed on the spike's pairs, which no cap can remove, and a loop elsewhere was cut); by
// CGAL, no cap face intersects anything and the input's own crossings are all that is left;
// genus 0 per component; 1 and 2 threads give the same loops and mesh.
TEST(DenoiseCapIntersections, CrossingsTheInputHadAreNotTheCaps) {
  int first_new_face = 0;
  const Mesh m = waisted_torus_with_piercing_spike(&first_new_face);
  const std::size_t input_pairs = testing::count_self_intersections(m);
  ASSERT_GT(input_pairs, 0u) << "the spike must pierce the wall";
  set_thread_count(1);
  const DenoiseResult r = denoise(m, DenoiseOptions{});
  ASSERT_EQ(r.loops.size(), 1u);
  const double waist = 2 * kPi * 0.85;
  EXPECT_NEAR(r.loops[0].length, waist, 0.05 * waist) << "the waist meridian itself";
  std::vector<int> expected_ids;
  for (int j = 0; j < 16; ++j) expected_ids.push_back(7 * 16 + j);
  std::vector<int> ids = r.loops[0].vertex_ids;
  std::sort(ids.begin(), ids.end());
  EXPECT_EQ(ids, expected_ids);
  EXPECT_EQ(r.loops[0].cap_intersections, 0u);
  EXPECT_EQ(r.report["search"]["loops_replaced_for_clean_caps"], 0);
  const auto pairs = testing::self_intersecting_pairs(r.mesh);
  for (const auto& [f, g] : pairs) EXPECT_LT(g, first_new_face) << "cap face " << g << " crosses face " << f;
  EXPECT_EQ(pairs.size(), input_pairs);
  for (const auto& c : analyze_topology(r.mesh).components) EXPECT_EQ(c.genus, 0);
  set_thread_count(2);
  const DenoiseResult two = denoise(m, DenoiseOptions{});
  set_thread_count(0);
  ASSERT_EQ(two.loops.size(), 1u);
  EXPECT_EQ(two.loops[0].vertex_ids, r.loops[0].vertex_ids);
  ASSERT_EQ(two.mesh.n_vertices(), r.mesh.n_vertices());
  for (auto v : r.mesh.vertices()) EXPECT_EQ(two.mesh.point(v), r.mesh.point(v)) << v.idx();
}

}  // namespace
}  // namespace cf
