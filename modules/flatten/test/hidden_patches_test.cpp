// Hidden wall cut out as patches (src/hidden_patches.cpp): a band whose finished map hides wall gives
// that wall (and a few rings around it) to a band of its own; the band keeps the map of the rest.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "../src/hidden_patches.h"
#include "colonflat/core/threads.h"
#include "colonflat/flatten/flatten.h"
#include "flatten_shapes.h"
#include "squeezed_grid.h"

namespace cf {
namespace {

using flat_detail::V2;
using flat_detail::V3;

// A flat 40 x 40 mm grid (1 mm cells) whose map squeezes the disk of radius 5 mm around (20, 20) by
// 0.2 each way (area ratio 0.04: hidden), stretched back out to the identity at radius 10 mm.
struct CrushedDisk {
  static constexpr int kN = 41;
  static constexpr double kR = 5, kOut = 10;
  flat_detail::SegmentWork w;
  flat_detail::Edges E;
  std::vector<char> degenerate;
  std::vector<std::vector<int>> vf;
  static double mapped(double r, double squeeze) {
    return r < kR ? squeeze * r : r < kOut ? squeeze * kR + (r - kR) * (kOut - squeeze * kR) / (kOut - kR) : r;
  }
  explicit CrushedDisk(double squeeze) {
    for (int j = 0; j < kN; ++j)
      for (int i = 0; i < kN; ++i) {
        const V2 q(i - 20.0, j - 20.0);
        const double r = q.norm();
        w.ann.p.emplace_back(i, j, 0.0);
        w.ann.src.push_back(int(w.ann.p.size()) - 1);
        w.emb.pos.push_back(V2(20, 20) + (r > 0 ? q * (mapped(r, squeeze) / r) : q));
      }
    test_shapes::grid_triangles(kN, kN, w.ann.t);
    w.emb.dy.assign(w.ann.t.size(), {0.0, 0.0, 0.0});
    w.emb.period = 1000;
    w.along.assign(w.ann.p.size(), 0.0);
    w.seg.area_3d = flat_detail::surface_area(w.ann);
    E = flat_detail::build_edges(w.ann.t);
    degenerate.assign(w.ann.t.size(), 0);
    vf = flat_detail::vertex_faces(w.ann);
  }
  double centre_distance(int f) const {
    const auto& t = w.ann.t[std::size_t(f)];
    const V3 c = (w.ann.p[std::size_t(t[0])] + w.ann.p[std::size_t(t[1])] + w.ann.p[std::size_t(t[2])]) / 3;
    return std::hypot(c.x() - 20, c.y() - 20);
  }
};

// The crushed disk (5 % of the band's wall) becomes one patch: every face inside it and every face
// the map shows below ratio 0.1 is in it, nothing farther than the disk plus the rings of cells
// around it, and it is a disk (one open end).
TEST(HiddenPatches, CrushedDiskIsOnePatchHoldingEveryHiddenFace) {
  const CrushedDisk g(0.2);
  const auto patches = flat_detail::hidden_patches(g.w, g.E, g.vf, g.degenerate, 0.1, 50.0);
  ASSERT_EQ(patches.size(), 1u);
  std::vector<char> in(g.w.ann.t.size(), 0);
  for (int f : patches[0]) in[std::size_t(f)] = 1;
  const double scale = 1.0;  // the map keeps the grid's total area (the identity outside radius 10)
  for (std::size_t f = 0; f < g.w.ann.t.size(); ++f) {
    const double ratio = g.w.emb.area2(g.w.ann, int(f)) * scale / flat_detail::face_area_3d(g.w.ann, int(f));
    if (g.centre_distance(int(f)) < CrushedDisk::kR - 1 || ratio < 0.1) EXPECT_TRUE(in[f]) << "face " << f;
    if (in[f]) EXPECT_LT(g.centre_distance(int(f)), CrushedDisk::kR + flat_detail::kPatchRings * std::sqrt(2.0) + 1.5);
  }
}

// A map that hides nothing (squeeze 0.5: ratio 0.25 >= 0.1), or hidden wall in clusters smaller than
// the minimum area, gives no patch.
TEST(HiddenPatches, NothingHiddenOrTooSmallGivesNoPatch) {
  const CrushedDisk mild(0.5);
  EXPECT_TRUE(flat_detail::hidden_patches(mild.w, mild.E, mild.vf, mild.degenerate, 0.1, 50.0).empty());
  const CrushedDisk g(0.2);
  EXPECT_TRUE(flat_detail::hidden_patches(g.w, g.E, g.vf, g.degenerate, 0.1, 200.0).empty());
}

// Cutting the patch out leaves the rest of the band with its map unchanged corner for corner, its
// wall area less the patch's, and the patch a surface of its own whose rim (neck) runs around the
// crushed disk (longer than the disk's circumference) through vertices the rest keeps.
TEST(HiddenPatches, CutLeavesTheRestsMapAsItWas) {
  CrushedDisk g(0.2);
  const flat_detail::SegmentWork before = g.w;
  const auto patches = flat_detail::hidden_patches(g.w, g.E, g.vf, g.degenerate, 0.1, 50.0);
  ASSERT_EQ(patches.size(), 1u);
  const flat_detail::PatchCut cut = flat_detail::cut_patches(g.w, g.E, g.degenerate, patches);
  ASSERT_EQ(cut.pieces.size(), 1u);
  EXPECT_EQ(cut.pieces[0].loops, 2u);  // a disk, opened along its ridge (patch_slit.h) into an annulus
  EXPECT_EQ(g.w.ann.t.size() + cut.pieces[0].surface.t.size() + 12, before.ann.t.size());  // less the slit's two end fans of 6 faces
  EXPECT_EQ(g.degenerate.size(), g.w.ann.t.size());
  EXPECT_EQ(g.w.emb.dy.size(), g.w.ann.t.size());
  EXPECT_NEAR(g.w.seg.area_3d + cut.area_mm2, before.seg.area_3d, 1e-9);
  for (std::size_t v = 0; v < g.w.ann.p.size(); ++v) {
    const int old = g.w.ann.src[v];  // the grid's vertex id
    EXPECT_EQ(g.w.emb.pos[v], before.emb.pos[std::size_t(old)]);
    EXPECT_EQ(g.w.ann.p[v], before.ann.p[std::size_t(old)]);
  }
  EXPECT_GT(cut.pieces[0].neck_mm, 2 * M_PI * CrushedDisk::kR);
  for (int v : cut.pieces[0].neck) EXPECT_GE(v, 0);
}

// Two patches side by side (the crushed disk's left and right halves, r < 8 mm) share a rim edge
// whose ends lie in no face of the rest: each patch's neck holds only vertices the rest keeps (valid
// band vertices, off the shared edge's inner ends), on its own side of the disk.
TEST(HiddenPatches, NeckOfPatchesSideBySideHoldsOnlyTheBandsVertices) {
  CrushedDisk g(0.2);
  std::vector<std::vector<int>> halves(2);
  for (std::size_t f = 0; f < g.w.ann.t.size(); ++f) {
    if (!(g.centre_distance(int(f)) < 8)) continue;
    const auto& t = g.w.ann.t[f];
    const double x = (g.w.ann.p[std::size_t(t[0])].x() + g.w.ann.p[std::size_t(t[1])].x() + g.w.ann.p[std::size_t(t[2])].x()) / 3;
    halves[x < 20 ? 0 : 1].push_back(int(f));
  }
  const flat_detail::PatchCut cut = flat_detail::cut_patches(g.w, g.E, g.degenerate, halves);
  ASSERT_EQ(cut.pieces.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    ASSERT_FALSE(cut.pieces[i].neck.empty());
    double mean_x = 0;
    for (int v : cut.pieces[i].neck) {
      ASSERT_GE(v, 0);
      ASSERT_LT(std::size_t(v), g.w.ann.p.size());
      mean_x += g.w.ann.p[std::size_t(v)].x() / double(cut.pieces[i].neck.size());
    }
    EXPECT_EQ(mean_x < 20, i == 0) << "patch " << i << " mean x " << mean_x;
  }
}

// A stalked polyp (6 mm head on a 1.6 mm stalk) left to the conformal map (area correction and
// balancing off) hides its head: below 99 % shown with patches off (--branch-min-area 0: nothing cut
// out), >= 99.5 % when the hidden head is cut out as a patch and flattened on its own; nothing
// flipped, the patch band marked as wall ("holds" = "wall", ends "rim" -> "tip"), the same map bit for bit with 1
// and 2 threads.
TEST(HiddenPatches, HiddenPolypHeadIsShownOnAPatch) {
  const TriangleList mesh = test_shapes::stalked_polyp();
  FlattenOptions o;
  o.area_correction_iterations = 0;
  o.balance_iterations = 0;
  FlattenOptions off = o;
  off.branch_min_area = 0;
  EXPECT_LT(flatten_colon(mesh, off).coverage.fraction, 0.99);
  set_thread_count(2);
  const FlatMap f = flatten_colon(mesh, o);
  set_thread_count(1);
  const FlatMap one = flatten_colon(mesh, o);
  set_thread_count(0);
  EXPECT_GE(f.coverage.fraction, 0.995);
  EXPECT_GE(f.segments.size(), 2u);
  EXPECT_TRUE(std::any_of(f.segments.begin(), f.segments.end(), [](const FlatSegment& s) {
    return s.kind == "branch" && s.holds == "wall" && s.x0_end == "rim" && s.x1_end == "tip";
  }));
  EXPECT_EQ(f.stats.flipped, 0u);
  ASSERT_EQ(one.uv.size(), f.uv.size());
  EXPECT_EQ(test_shapes::uv_differences(one, f), 0u);
}

}  // namespace
}  // namespace cf
