// Stump removal (stumps.h, DenoiseOptions::remove_stumps): the fingers left where thin strands
// were cut go, caps that close holes stay, topology and embedding are kept.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "bench_meshes.h"
#include "colonflat/core/error.h"
#include "colonflat/core/topology.h"
#include "colonflat/denoise/denoise.h"
#include "self_intersections.h"

namespace cf {
namespace {

double radius_range(const Mesh& m, bool largest) {
  double r = largest ? 0 : 1e300;
  for (auto v : m.vertices()) r = largest ? std::max(r, m.point(v).norm()) : std::min(r, m.point(v).norm());
  return r;
}
double max_radius(const Mesh& m) { return radius_range(m, true); }
double min_radius(const Mesh& m) { return radius_range(m, false); }

// A ball (R 15 mm) pierced by a 1 mm strand along a chord 5.4 mm from its centre, like a tissue
// bridge across the lumen. Cutting the strand leaves two tubular fingers reaching deep into the
// ball; removing stumps takes both: genus 0, the surface back on the sphere, one component, no
// new self-intersection, two removals reported.
TEST(DenoiseStumps, FingersOfACutStrandAreRemoved) {
  const Mesh m = bench::sphere_with_strand(15, 1.0, 0.4);
  ASSERT_EQ(*analyze_topology(m).genus, 1);
  const DenoiseResult kept = denoise(m, DenoiseOptions{});
  EXPECT_LT(min_radius(kept.mesh), 8.0) << "without removal the fingers reach deep inside";
  DenoiseOptions o;
  o.remove_stumps = 30;
  const DenoiseResult r = denoise(m, o);
  EXPECT_EQ(*r.after.genus, 0);
  EXPECT_EQ(r.after.components.size(), 1u);
  EXPECT_TRUE(r.after.closed);
  EXPECT_TRUE(r.after.manifold);
  EXPECT_TRUE(r.after.consistently_oriented);
  EXPECT_GT(min_radius(r.mesh), 14.0);
  EXPECT_EQ(r.report["stumps"]["removed"].get<int>(), 2);
  EXPECT_LT(r.mesh.n_faces(), kept.mesh.n_faces());
  EXPECT_EQ(testing::count_self_intersections(r.mesh), testing::count_self_intersections(m));
}

// Too long for max_length: the fingers stay.
TEST(DenoiseStumps, FingersLongerThanTheLimitStay) {
  const Mesh m = bench::sphere_with_strand(15, 1.0, 0.4);
  DenoiseOptions o;
  o.remove_stumps = 2;
  const DenoiseResult r = denoise(m, o);
  EXPECT_EQ(r.report["stumps"]["removed"].get<int>(), 0);
  EXPECT_LT(min_radius(r.mesh), 8.0);
}

// Caps that close holes (tunnel loops under the arches, the default policy's choice here) end no
// finger: the arches stay where they are.
TEST(DenoiseStumps, HoleCapsAreNoStumps) {
  const Mesh m = bench::sphere_with_handles(25, 12, 0.6, 3);
  DenoiseOptions o;
  o.remove_stumps = 20;
  const DenoiseResult r = denoise(m, o);
  EXPECT_EQ(*r.after.genus, 0);
  EXPECT_GT(max_radius(r.mesh), 28.0);
  EXPECT_EQ(testing::count_self_intersections(r.mesh), testing::count_self_intersections(m));
}

// Invalid settings are refused: negative length, or with the paper's method.
TEST(DenoiseStumps, InvalidOptionsAreRejected) {
  const Mesh m = bench::sphere_with_handles(25, 2, 0.6, 3);
  DenoiseOptions o;
  o.remove_stumps = -1;
  EXPECT_THROW(denoise(m, o), UsageError);
  o.remove_stumps = 10;
  o.method = "paper";
  EXPECT_THROW(denoise(m, o), UsageError);
}

}  // namespace
}  // namespace cf
