// The flat map does not depend on the number of worker threads (--threads): segments flattened
// side by side, side branches beside their colon, per-face loops in fixed blocks, solves column
// by column.
#include <gtest/gtest.h>

#include <cmath>

#include "colonflat/core/synthetic.h"
#include "colonflat/core/threads.h"
#include "colonflat/flatten/flatten.h"
#include "../src/face_blocks.h"
#include "../src/factor_memory.h"
#include "../src/flatten_internal.h"
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

// With 1 and with 2 threads every flat vertex lands on the same coordinates (bit for bit), with the
// same triangles, bands, coverage and distortion; the case has two segments and a cut-off branch,
// so the segments, the branch and the per-face loops (regions of several blocks) all run side by side.
TEST(FlattenThreads, OneAndTwoThreadsGiveTheSameMap) {
  const TriangleList mesh = two_segments_with_a_branch();
  ASSERT_GT(mesh.triangles.size(), 4 * 8192u);  // several blocks of faces per loop
  const FlatMap one = test_shapes::flatten_with_threads(mesh, 1);
  const FlatMap two = test_shapes::flatten_with_threads(mesh, 2);
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

// An open cylinder along x (radius 10 mm, 200 mm long, 400 rings of 64 vertices: 51 200 faces, seven
// blocks), u = x / 200.
flat_detail::Surface cylinder_band() {
  flat_detail::Surface s;
  constexpr int kRings = 401, kAround = 64;
  for (int i = 0; i < kRings; ++i)
    for (int j = 0; j < kAround; ++j) {
      const double a = 2 * M_PI * j / kAround;
      s.p.emplace_back(200.0 * i / (kRings - 1), 10 * std::cos(a), 10 * std::sin(a));
    }
  for (int i = 0; i + 1 < kRings; ++i)
    for (int j = 0; j < kAround; ++j) {
      const int a = i * kAround + j, b = i * kAround + (j + 1) % kAround;
      s.t.push_back({a, b, b + kAround});
      s.t.push_back({a, b + kAround, a + kAround});
    }
  return s;
}

flat_detail::Centreline centreline_on_threads(const flat_detail::Surface& s, const std::vector<char>& use, int threads) {
  std::vector<double> u(s.p.size());
  for (std::size_t v = 0; v < s.p.size(); ++v) u[v] = s.p[v].x() / 200.0;
  set_thread_count(threads);
  flat_detail::Centreline c = centreline_from_u(s, u, use, {0, 0, 0}, {200, 0, 0});
  set_thread_count(0);
  return c;
}

// The centreline's face samples and arc lengths (computed in blocks of faces on the worker threads)
// give the same bits on 1, 2 and 3 threads, with some faces left out; with all faces in, it is the
// cylinder's axis (the ring centroids), 200 mm long, with the wall area spread evenly over u.
TEST(FlattenThreads, CentrelineIsTheSameOnOneTwoThreeThreadsAndFollowsTheAxis) {
  const flat_detail::Surface s = cylinder_band();
  ASSERT_GT(s.t.size(), 6 * flat_detail::kFaceBlock);
  std::vector<char> some(s.t.size(), 1);
  for (std::size_t f = 3; f < s.t.size(); f += 7) some[f] = 0;
  const flat_detail::Centreline one = centreline_on_threads(s, some, 1);
  for (int threads : {2, 3}) {
    const flat_detail::Centreline c = centreline_on_threads(s, some, threads);
    EXPECT_EQ(c.points, one.points) << threads;
    EXPECT_EQ(c.knot_u, one.knot_u) << threads;
    EXPECT_EQ(c.knot_s, one.knot_s) << threads;
    EXPECT_EQ(c.area_cdf, one.area_cdf) << threads;
    EXPECT_EQ(c.length, one.length) << threads;
  }
  const flat_detail::Centreline axis = centreline_on_threads(s, std::vector<char>(s.t.size(), 1), 2);
  EXPECT_NEAR(axis.length, 200.0, 1e-3);
  ASSERT_GT(axis.points.size(), 20u);
  for (const auto& p : axis.points) EXPECT_LT(std::hypot(p[1], p[2]), 1e-9);
  for (std::size_t k = 0; k < axis.area_cdf.size(); k += 256)
    EXPECT_NEAR(axis.area_cdf[k], double(k) / double(axis.area_cdf.size() - 1), 3e-3) << k;
  for (double x : {25.0, 100.0, 180.0}) EXPECT_NEAR(axis.s_of_u(x / 200), x, 0.5) << x;
}

// The two-segment case with 3 threads (blocks of faces split unevenly over the threads: the
// conformal maps' signed areas and bad-face counts, the centrelines, the untangling's folds) lands
// every flat vertex where 1 thread does.
TEST(FlattenThreads, ThreeThreadsGiveTheOneThreadMap) {
  const TriangleList mesh = two_segments_with_a_branch();
  const FlatMap one = test_shapes::flatten_with_threads(mesh, 1);
  const FlatMap three = test_shapes::flatten_with_threads(mesh, 3);
  ASSERT_GE(one.segments.size(), 3u);
  EXPECT_EQ(one.uv, three.uv);
  EXPECT_EQ(one.source_vertex, three.source_vertex);
  EXPECT_EQ(one.triangles, three.triangles);
  EXPECT_EQ(one.coverage.fraction, three.coverage.fraction);
}

// The band left once its side branch is cut has its faces prepared (wall area, degenerate and
// fixed vertices, vertex faces) beside its re-solve on 2 threads, before it on 1: its wall area,
// length and period (conformal rectangle: length x period = wall area) are the same bits either way.
TEST(FlattenThreads, RestPreparedBesideItsResolveGivesTheSameBand) {
  const TriangleList mesh = test_shapes::pouch_behind_neck(3.0);
  const FlatMap one = test_shapes::flatten_with_threads(mesh, 1);
  const FlatMap two = test_shapes::flatten_with_threads(mesh, 2);
  ASSERT_GE(one.segments.size(), 2u);  // the colon and its cut-off branch
  ASSERT_EQ(one.segments.size(), two.segments.size());
  for (std::size_t k = 0; k < one.segments.size(); ++k) {
    EXPECT_GT(one.segments[k].area_3d, 0.0);
    EXPECT_EQ(one.segments[k].area_3d, two.segments[k].area_3d);
    EXPECT_EQ(one.segments[k].length, two.segments[k].length);
    EXPECT_EQ(one.segments[k].period, two.segments[k].period);
  }
  EXPECT_EQ(one.uv, two.uv);
}

// A colon segment large enough to get its nested dissection order (computed beside its first
// conformal map, used by the re-solve after its side branch is cut and by the whole-band area
// correction its wide pouch needs): a tube with a wide pouch and a pouch behind a 3 mm neck, at 0.42 mm.
TriangleList large_colon_with_a_branch() {
  return test_shapes::surface_of(
      [](const Eigen::Vector3d& p) {
        const double tube = std::min(test_shapes::capsule(p, {0, 0, 0}, {200, 0, 0}, 12),
                                     (p - Eigen::Vector3d(70, 8, 0)).norm() - 28);
        const double channel = test_shapes::capsule(p, {150, 0, 0}, {150, 32, 0}, 3.0);
        const double pouch = (p - Eigen::Vector3d(150, 50, 0)).norm() - 22;
        return std::min({tube, channel, pouch});
      },
      {-15, -22, -31}, {215, 75, 31}, 0.42);
}

// A colon with the nested dissection order (more vertices than kNestedDissectionMinVertices) is
// flattened bit for bit the same with 1 and 2 threads (the order is computed on a second thread
// with 2, where needed with 1), its branch cut off and its wall shown.
TEST(FlattenThreads, LargeColonWithItsDissectionOrderIsTheSameForOneAndTwoThreads) {
  const TriangleList mesh = large_colon_with_a_branch();
  ASSERT_GE(mesh.points.size(), flat_detail::kNestedDissectionMinVertices);
  const FlatMap one = test_shapes::flatten_with_threads(mesh, 1);
  const FlatMap two = test_shapes::flatten_with_threads(mesh, 2);
  std::size_t branches = 0;
  for (const auto& s : one.segments) branches += s.kind == "branch";
  EXPECT_GE(branches, 1u);
  ASSERT_EQ(one.uv.size(), two.uv.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < one.uv.size(); ++i)
    differ += one.uv[i][0] != two.uv[i][0] || one.uv[i][1] != two.uv[i][1] || one.source_vertex[i] != two.source_vertex[i];
  EXPECT_EQ(differ, 0u);
  EXPECT_EQ(one.triangles, two.triangles);
  EXPECT_EQ(one.coverage.fraction, two.coverage.fraction);
  EXPECT_GE(one.coverage.fraction, 0.995);
  EXPECT_EQ(one.stats.flipped, 0u);
}

// flatten_colon keeps no factor memory once it returns: the large colon's factorisations did use
// the block cache (blocks of >= 32 MiB), and none of its blocks is still kept afterwards.
TEST(FlattenThreads, LargeColonLeavesNoFactorMemoryKept) {
  const TriangleList mesh = large_colon_with_a_branch();
  const flat_detail::BlockCache::Stats before = flat_detail::cholmod_block_cache().stats();
  const FlatMap flat = test_shapes::flatten_with_threads(mesh, 2);
  const flat_detail::BlockCache::Stats after = flat_detail::cholmod_block_cache().stats();
  EXPECT_GE(flat.coverage.fraction, 0.995);
  EXPECT_GT(after.fresh + after.reused, before.fresh + before.reused);
  EXPECT_EQ(after.kept, 0u);
  EXPECT_EQ(after.kept_bytes, 0u);
}

}  // namespace
}  // namespace cf
