// The flat map does not depend on the number of worker threads (--threads): segments flattened
// side by side, side branches beside their colon, per-face loops in fixed blocks, solves column
// by column.
#include <gtest/gtest.h>

#include "colonflat/core/synthetic.h"
#include "colonflat/core/threads.h"
#include "colonflat/flatten/flatten.h"
#include "flatten_shapes.h"

namespace cf {
namespace {

// Two colon segments: a tube with a pouch behind a 3 mm neck (cut off as a side branch) and, apart
// from it, a plain closed tube.
TriangleList two_segments_with_a_branch() {
  const TriangleList tube = test_shapes::surface_of(
      [](const Eigen::Vector3d& p) { return test_shapes::capsule(p, {0, 0, 0}, {120, 0, 0}, 10); }, {-12, -12, -12},
      {132, 12, 12}, 1.5);
  return synthetic::disjoint_union(test_shapes::pouch_behind_neck(3.0), synthetic::translated(tube, 0, 0, 80));
}

FlatMap flatten_with_threads(const TriangleList& mesh, int threads) {
  set_thread_count(threads);
  FlatMap f = flatten_colon(mesh);
  set_thread_count(0);
  return f;
}

// With 1 and with 2 threads every flat vertex lands on the same coordinates (bit for bit), with the
// same triangles, bands, coverage and distortion; the case has two segments and a cut-off branch,
// so the segments, the branch and the per-face loops (regions of several blocks) all run side by side.
TEST(FlattenThreads, OneAndTwoThreadsGiveTheSameMap) {
  const TriangleList mesh = two_segments_with_a_branch();
  ASSERT_GT(mesh.triangles.size(), 4 * 8192u);  // several blocks of faces per loop
  const FlatMap one = flatten_with_threads(mesh, 1);
  const FlatMap two = flatten_with_threads(mesh, 2);
  std::size_t branches = 0;
  for (const auto& s : one.segments) branches += s.kind == "branch";
  ASSERT_GE(one.segments.size(), 3u);
  ASSERT_GE(branches, 1u);
  ASSERT_EQ(one.segments.size(), two.segments.size());
  ASSERT_EQ(one.uv.size(), two.uv.size());
  ASSERT_EQ(one.triangles.size(), two.triangles.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < one.uv.size(); ++i)
    differ += one.uv[i][0] != two.uv[i][0] || one.uv[i][1] != two.uv[i][1] ||
              one.source_vertex[i] != two.source_vertex[i];
  EXPECT_EQ(differ, 0u);
  EXPECT_EQ(one.triangles, two.triangles);
  EXPECT_EQ(one.coverage.fraction, two.coverage.fraction);
  EXPECT_EQ(one.stats.qc_mean, two.stats.qc_mean);
  EXPECT_EQ(one.stats.area_p05, two.stats.area_p05);
  for (std::size_t k = 0; k < one.segments.size(); ++k) {
    EXPECT_EQ(one.segments[k].kind, two.segments[k].kind);
    EXPECT_EQ(one.segments[k].faces, two.segments[k].faces);
    EXPECT_EQ(one.segments[k].corrected_iterations, two.segments[k].corrected_iterations);
  }
  EXPECT_EQ(one.stats.flipped, 0u);
}

}  // namespace
}  // namespace cf
