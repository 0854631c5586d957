// Real and real-like colon surfaces: the real CT colonography mask (reconstructed), the real GCA
// large-intestine surfaces, and colon-like generated surfaces (long contact handle, air bridges
// to a small-bowel loop, wide curved tissue strands, diverticulum-like hooks): genus 0 per
// component, components kept, closed, manifold, oriented, every loop described, and no cap
// intersection (the module's own count and CGAL, independently).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "bench_meshes.h"
#include "colonflat/core/mesh_io.h"
#include "colonflat/core/threads.h"
#include "colonflat/denoise/denoise.h"
#include "colonflat/reconstruct/reconstruct.h"
#include "colonflat/segment/segment.h"
#include "colonflat/volume/volume_io.h"
#include "self_intersections.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

// Boxes around every loop, grown by `margin` mm: where the caps are.
std::vector<std::array<Vec3, 2>> loop_boxes(const std::vector<LoopRecord>& loops, double margin) {
  std::vector<std::array<Vec3, 2>> boxes;
  for (const auto& L : loops) {
    Vec3 lo(1e300, 1e300, 1e300), hi(-1e300, -1e300, -1e300);
    for (const auto& p : L.points) {
      lo.minimize(p);
      hi.maximize(p);
    }
    boxes.push_back({lo - Vec3(margin, margin, margin), hi + Vec3(margin, margin, margin)});
  }
  return boxes;
}

// The acceptance properties of issue 12 on one surface; `whole_cgal` checks the whole mesh with
// CGAL, otherwise only the faces near the loops (where surgery changed anything).
DenoiseResult expect_clean_denoise(const Mesh& m, const std::string& what, bool whole_cgal) {
  const TopologyReport before = analyze_topology(m);
  DenoiseResult r = denoise(m, DenoiseOptions{});
  EXPECT_EQ(r.loops.size(), static_cast<std::size_t>(*before.genus)) << what;
  EXPECT_EQ(r.after.components.size(), before.components.size()) << what;
  for (const auto& c : r.after.components) EXPECT_EQ(c.genus, 0) << what;
  EXPECT_TRUE(r.after.closed) << what;
  EXPECT_TRUE(r.after.manifold) << what;
  EXPECT_TRUE(r.after.consistently_oriented) << what;
  EXPECT_EQ(r.report["totals"]["cap_intersections"].get<std::size_t>(), 0u) << what;
  for (const auto& L : r.loops) {
    EXPECT_FALSE(L.separating) << what;
    EXPECT_GT(L.diameter_mm, 0) << what;
    EXPECT_LE(L.diameter_mm, L.length / 2 + 1e-9) << what;  // a closed curve spans at most half its length
    EXPECT_GE(L.cross_section_area_mm2, 0) << what;
  }
  const auto boxes = loop_boxes(r.loops, 2.0);
  const std::size_t cgal_before = whole_cgal ? testing::count_self_intersections(m) : testing::count_self_intersections_in(m, boxes);
  const std::size_t cgal_after =
      whole_cgal ? testing::count_self_intersections(r.mesh) : testing::count_self_intersections_in(r.mesh, boxes);
  EXPECT_EQ(cgal_after, cgal_before) << what << ": surgery introduced self-intersections";
  return r;
}

// A colon-like surface (1 mm voxels): long contact handle, bridges, strands and hooks are all
// cut cleanly, and the exact loops are never longer in total than the paper's method.
TEST(DenoiseRealLike, ColonLikeSurfaceCleanAndNotLongerThanPaper) {
  const Mesh m = bench::colon_like_surface({1.0, 60, true, true, true});
  ASSERT_GE(*analyze_topology(m).genus, 5);  // contact, bridge, two strands, two hooks
  const DenoiseResult r = expect_clean_denoise(m, "colon-like", true);
  double longest = 0;
  for (const auto& L : r.loops) longest = std::max(longest, L.length);
  EXPECT_GT(longest, 100.0) << "the contact's handle is long (around a 60 mm contact)";
  DenoiseOptions p;
  p.method = "paper";
  const DenoiseResult pr = denoise(m, p);
  EXPECT_LE(r.report["totals"]["loop_length_mm"].get<double>(),
            pr.report["totals"]["loop_length_mm"].get<double>() * (1 + 1e-9));
}

// --max-loop-length on the colon-like surface: the long contact handle is kept (genus 1 left),
// everything shorter is cut, and the stop reason says so.
TEST(DenoiseRealLike, MaxLoopLengthKeepsTheLongContactHandle) {
  const Mesh m = bench::colon_like_surface({1.0, 60, true, true, true});
  DenoiseOptions o;
  o.max_loop_length = 100;
  const DenoiseResult r = denoise(m, o);
  EXPECT_EQ(r.report["stop_reason"], "no loop shorter than --max-loop-length remains");
  for (const auto& L : r.loops) EXPECT_LT(L.length, 100.0);
  EXPECT_GE(*r.after.genus, 1);
}

// Denoises `m` with `threads` worker threads (cf::thread_count(), the global --threads).
DenoiseResult denoise_with_threads(const Mesh& m, int threads, const DenoiseOptions& o = {}) {
  set_thread_count(threads);
  DenoiseResult r = denoise(m, o);
  set_thread_count(0);
  return r;
}

// The same loops (vertex ids in the same order, same lengths) and the same output mesh, point by
// point and face by face, with 1 and with `threads` threads.
void expect_same_result(const DenoiseResult& a, const DenoiseResult& b) {
  ASSERT_EQ(a.loops.size(), b.loops.size());
  for (std::size_t i = 0; i < a.loops.size(); ++i) {
    EXPECT_EQ(a.loops[i].vertex_ids, b.loops[i].vertex_ids) << i;
    EXPECT_EQ(a.loops[i].length, b.loops[i].length) << i;
  }
  ASSERT_EQ(a.mesh.n_vertices(), b.mesh.n_vertices());
  ASSERT_EQ(a.mesh.n_faces(), b.mesh.n_faces());
  std::size_t points_differ = 0, faces_differ = 0;
  for (auto v : a.mesh.vertices()) points_differ += a.mesh.point(v) != b.mesh.point(v);
  for (auto f : a.mesh.faces()) {
    std::vector<int> fa, fb;
    for (auto v : a.mesh.fv_range(f)) fa.push_back(v.idx());
    for (auto v : b.mesh.fv_range(f)) fb.push_back(v.idx());
    faces_differ += fa != fb;
  }
  EXPECT_EQ(points_differ, 0u);
  EXPECT_EQ(faces_differ, 0u);
}

// A sphere with 24 handles far apart: batches of spatially separated group searches and every
// homology build's pruning run on 2 threads (both counted), and the loops and the output mesh are
// identical to 1 thread's.
TEST(DenoiseThreads, OneAndTwoThreadsGiveTheSameLoopsAndMeshOnManyHandles) {
  const Mesh m = bench::sphere_with_handles(30, 24, 0.6);
  const DenoiseResult a = denoise_with_threads(m, 1), b = denoise_with_threads(m, 2);
  EXPECT_EQ(a.report["search"]["parallel_search_pairs"].get<long long>(), 0);
  EXPECT_GT(b.report["search"]["parallel_search_pairs"].get<long long>(), 0);
  // Every homology build of the 2-thread run (the set-up's first one too) pruned on the helper.
  EXPECT_EQ(a.report["search"]["homology_builds_pruned_beside"].get<int>(), 0);
  EXPECT_GE(b.report["search"]["homology_builds"].get<int>(), 1);
  EXPECT_EQ(b.report["search"]["homology_builds_pruned_beside"], b.report["search"]["homology_builds"]);
  EXPECT_EQ(b.report["genus_after"], 0);
  EXPECT_EQ(a.loops.size(), 24u);
  expect_same_result(a, b);
}

// The input's topology handed in (as the stage does with orient_mesh_input's): the input is not
// analysed again (analysis time 0), and the loops and the output mesh are those of a run that
// analyses it, with 1 and 2 threads (the guard grid then built on the helper from the input). A
// report of another mesh is not taken (analysed again, the same result).
TEST(DenoiseThreads, KnownInputTopologyIsTakenWithTheSameResult) {
  const Mesh m = bench::sphere_with_handles(30, 6, 0.6);
  const TopologyReport known = analyze_topology(m);
  const DenoiseResult a = denoise_with_threads(m, 1);
  auto with_known = [&](int threads, const TopologyReport& t) {
    set_thread_count(threads);
    DenoiseResult r = denoise(m, DenoiseOptions{}, {}, &t);
    set_thread_count(0);
    return r;
  };
  EXPECT_GT(a.report["time_s"]["analysis"].get<double>(), 0.0);
  for (int threads : {1, 2}) {
    SCOPED_TRACE(threads);
    const DenoiseResult b = with_known(threads, known);
    EXPECT_EQ(b.report["time_s"]["analysis"].get<double>(), 0.0);
    EXPECT_EQ(b.report["genus_before"], a.report["genus_before"]);
    EXPECT_EQ(b.report["genus_after"], 0);
    expect_same_result(a, b);
  }
  const TopologyReport other = analyze_topology(bench::sphere_with_handles(20, 2, 0.6));
  const DenoiseResult c = with_known(2, other);
  EXPECT_GT(c.report["time_s"]["analysis"].get<double>(), 0.0);
  expect_same_result(a, c);
}

// The colon-like surface (long contact handle, surgery on top of surgery, crossing families for
// the last loop): identical loops and mesh with 1, 2 and 3 threads.
TEST(DenoiseThreads, ColonLikeSurfaceIsTheSameForAnyThreadCount) {
  const Mesh m = bench::colon_like_surface({1.0, 60, true, true, true});
  const DenoiseResult a = denoise_with_threads(m, 1);
  EXPECT_EQ(a.report["genus_after"], 0);
  for (int threads : {2, 3}) {
    SCOPED_TRACE(threads);
    expect_same_result(a, denoise_with_threads(m, threads));
  }
}

// The colon-like surface's last handles leave batches of one group search: with 2 threads the
// group the next batch forms is searched ahead beside it (some taken), and the searches, settled
// vertices, loops and mesh are those of the 1-thread run, which searches nothing ahead.
TEST(DenoiseThreads, GroupsSearchedAheadChangeNoSearchLoopOrMesh) {
  const Mesh m = bench::colon_like_surface({1.0, 60, true, true, true});
  const DenoiseResult a = denoise_with_threads(m, 1), b = denoise_with_threads(m, 2);
  const auto& sa = a.report["search"];
  const auto& sb = b.report["search"];
  EXPECT_EQ(sa["group_searches_ahead"].get<long long>(), 0);
  EXPECT_GT(sb["group_searches_ahead_taken"].get<long long>(), 0);
  EXPECT_LE(sb["group_searches_ahead_taken"].get<long long>(), sb["group_searches_ahead"].get<long long>());
  for (const char* key : {"searches", "settled_vertices", "settled_vertices_alone", "group_searches", "bounds_spread"})
    EXPECT_EQ(sa[key], sb[key]) << key;
  expect_same_result(a, b);
}

// A handle removed through the crossing-loop fallback (no meridian of the blocked torus can be
// capped cleanly, the longitude is cut): identical loops and mesh with 1 and 2 threads.
TEST(DenoiseThreads, CrossingLoopFallbackIsTheSameForAnyThreadCount) {
  const Mesh m = bench::blocked_torus(bench::Blocker::kCoreRing);
  const DenoiseResult a = denoise_with_threads(m, 1);
  EXPECT_EQ(a.report["search"]["loops_replaced_by_crossing_loop"], 1);
  EXPECT_EQ(a.report["genus_after"], 0);
  expect_same_result(a, denoise_with_threads(m, 2));
}

// A handle removed through a loop of the same class away from the blocked meridian (front caps
// off; the fallback's searches run two sources at a time on the worker's threads): identical
// loops and mesh with 1 and 2 threads.
TEST(DenoiseThreads, SameClassFallbackIsTheSameForAnyThreadCount) {
  const Mesh m = bench::blocked_torus(bench::Blocker::kRod);
  DenoiseOptions o;
  o.front_caps = false;
  const DenoiseResult a = denoise_with_threads(m, 1, o);
  EXPECT_EQ(a.report["search"]["loops_replaced_for_clean_caps"], 1);
  EXPECT_EQ(a.report["genus_after"], 0);
  expect_same_result(a, denoise_with_threads(m, 2, o));
}

// The real GCA large-intestine surfaces (genus 1): one loop, clean caps (whole-mesh CGAL).
TEST(DenoiseReal, GcaLargeIntestine) {
  for (const char* f : {"gca_large_intestine_20k.vtk", "gca_large_intestine_100k.vtk"}) {
    const fs::path p = fs::path(COLONFLAT_SHARED_DIR) / "real" / f;
    if (!fs::exists(p)) GTEST_SKIP() << p << " missing";
    expect_clean_denoise(load_mesh(p).mesh, f, true);
  }
}

// The real CT colonography mask, reconstructed with the defaults (1.39 M faces, genus 18):
// every acceptance property, CGAL checked around the loops.
TEST(DenoiseReal, CtcLumenMaskA) {
  const fs::path p = fs::path(COLONFLAT_SHARED_DIR) / "real" / "ctc_lumen_mask_a.nii.gz";
  if (!fs::exists(p)) GTEST_SKIP() << p << " missing";
  const Mesh m = reconstruct_surface(read_mask(p).GetPointer(), ReconstructOptions{});
  expect_clean_denoise(m, "ctc_lumen_mask_a", false);
}

// The real prone CT, segmented and reconstructed with the defaults as `colonflat run` does (2.13 M
// faces, genus 95 in session 20): every acceptance property, CGAL checked around the loops. Its
// 65.8 mm handle (a window in a thin wall between two colon limbs) was kept with 301 intersecting
// cap pairs until the restricted caps were also tried left ring first (its 84.2 mm replacement).
TEST(DenoiseReal, CtcProneA) {
  const fs::path p = fs::path(COLONFLAT_SHARED_DIR) / "real" / "ctc_prone_a.nrrd";
  if (!fs::exists(p)) GTEST_SKIP() << p << " missing";
  const CtImage::Pointer ct = read_ct_volume(p);
  const MaskImage::Pointer mask = segment_colon(ct.GetPointer());
  const Mesh m = reconstruct_surface(mask.GetPointer(), ct.GetPointer(), ReconstructOptions{});
  const DenoiseResult r = expect_clean_denoise(m, "ctc_prone_a", false);
  std::printf("ctc_prone_a: %zu faces, %zu loops\n", m.n_faces(), r.loops.size());
}

}  // namespace
}  // namespace cf
