// A fork of the lumen (a limb of the tube's own girth, cut off as a side branch): the colon band
// keeps a hole as wide as itself, and the strip of wall along that hole's rim is shown.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>

#include "../src/cut_rims.h"
#include "../src/flatten_internal.h"
#include "colonflat/core/threads.h"
#include "colonflat/flatten/flatten.h"
#include "flatten_shapes.h"

namespace cf {
namespace {

// A tube (radius 12 mm) forking into a blind limb of radius 11 mm: the limb is cut off at a neck
// about the tube's girth, and the colon band left with that hole shows >= 99.5 % of its wall, with
// area ratio p05 >= 0.2 and nothing flipped (with the rim held where the conformal map put it, the
// strip along it stays crushed below ratio 0.1). The same map, bit for bit, with 1 and 2 threads.
TEST(FlattenFork, LimbSizedBranchLeavesItsRimStripShown) {
  const TriangleList mesh = test_shapes::tube_with_limb(11.0);
  const FlatMap f = test_shapes::flatten_with_threads(mesh, 2);
  ASSERT_GE(f.segments.size(), 2u);
  const FlatSegment& colon = f.segments[0];
  const FlatSegment& limb = f.segments[1];
  EXPECT_EQ(limb.kind, "branch");
  EXPECT_GT(limb.neck_mm, 0.7 * 2 * M_PI * 12);  // a fork: the neck is about the band's girth
  EXPECT_GE(colon.coverage.fraction, 0.995);
  EXPECT_GE(colon.stats.area_p05, 0.2);
  EXPECT_EQ(colon.stats.flipped, 0u);
  EXPECT_EQ(colon.crowded_faces, 0u);
  const FlatMap one = test_shapes::flatten_with_threads(mesh, 1);
  ASSERT_EQ(one.uv.size(), f.uv.size());
  EXPECT_EQ(test_shapes::uv_differences(one, f), 0u);
  EXPECT_EQ(one.triangles, f.triangles);
}


// A flat ring (3D: 10 mm <= radius <= 30 mm, 64 sectors, rings as square as the sectors) whose map
// keeps the hole's rim at 55 % of its length and crushes the 3.7 mm strip along it radially (x 0.05),
// the rest stretched out to the outer circle (kept): the band around a limb-sized branch's hole.
struct CrushedRim {
  static constexpr int kSectors = 64;
  flat_detail::SegmentWork w;
  std::vector<char> fixed, ends, degenerate;
  std::vector<std::vector<int>> vf;
  int rings = 0;
  static double mapped(double r) { return r < 13.7 ? 5.5 + 0.05 * (r - 10) : 5.685 + (r - 13.7) * (30 - 5.685) / (30 - 13.7); }
  CrushedRim() {
    std::vector<double> radius{10};
    while (radius.back() < 30) radius.push_back(std::min(30.0, radius.back() * (1 + 2 * M_PI / kSectors)));
    rings = int(radius.size());
    for (int k = 0; k < rings; ++k)
      for (int j = 0; j < kSectors; ++j) {
        const double a = 2 * M_PI * j / kSectors;
        w.ann.p.emplace_back(radius[k] * std::cos(a), radius[k] * std::sin(a), 0.0);
        w.emb.pos.emplace_back(mapped(radius[k]) * std::cos(a), mapped(radius[k]) * std::sin(a));
        fixed.push_back(k == 0 || k == rings - 1), ends.push_back(k == rings - 1);
      }
    const auto id = [](int k, int j) { return k * kSectors + (j % kSectors); };
    for (int k = 0; k + 1 < rings; ++k)
      for (int j = 0; j < kSectors; ++j) {
        w.ann.t.push_back({id(k, j), id(k + 1, j + 1), id(k, j + 1)});  // counter-clockwise
        w.ann.t.push_back({id(k, j), id(k + 1, j), id(k + 1, j + 1)});
      }
    w.emb.dy.assign(w.ann.t.size(), {0.0, 0.0, 0.0});
    w.emb.period = 1e6;  // not periodic
    degenerate.assign(w.ann.t.size(), 0);
    vf = flat_detail::vertex_faces(w.ann);
  }
  // Wall (3D mm^2) of the strip along the rim shown below ratio 0.1 at the map's area scale.
  double strip_hidden() const {
    double a2 = 0, a3 = 0, hidden = 0;
    for (std::size_t f = 0; f < w.ann.t.size(); ++f) a2 += w.emb.area2(w.ann, int(f)), a3 += flat_detail::face_area_3d(w.ann, int(f));
    for (std::size_t f = 0; f < w.ann.t.size(); ++f) {
      const double r3 = flat_detail::face_area_3d(w.ann, int(f));
      if (w.emb.area2(w.ann, int(f)) * a3 / a2 < 0.1 * r3) hidden += r3;
    }
    return hidden;
  }
};

// The local passes open the strip along a round hole's rim (wall hidden below ratio 0.1: > 100 mm^2
// before, < 1 % of it after) with no face folded, and the rim gives way: its vertices move (before
// this change every boundary vertex was held), while the outer circle (an end) stays where it was.
TEST(FlattenFork, RoundRimMovesAndTheStripAlongItOpens) {
  CrushedRim rim;
  const CrushedRim start;
  const double before = rim.strip_hidden();
  ASSERT_GT(before, 100.0);
  flat_detail::local_area_passes(rim.w, flat_detail::build_edges(rim.w.ann.t), rim.vf, rim.fixed, rim.ends, rim.degenerate, FlattenOptions{}, false, true);
  EXPECT_LT(rim.strip_hidden(), 0.01 * before);
  for (std::size_t f = 0; f < rim.w.ann.t.size(); ++f) EXPECT_GT(rim.w.emb.area2(rim.w.ann, int(f)), 0.0);
  std::size_t rim_moved = 0, ends_moved = 0;
  for (std::size_t v = 0; v < start.w.emb.pos.size(); ++v) {
    const bool moved = rim.w.emb.pos[v] != start.w.emb.pos[v];
    rim_moved += moved && start.fixed[v] && !start.ends[v], ends_moved += moved && start.ends[v];
  }
  EXPECT_EQ(rim_moved, std::size_t(CrushedRim::kSectors));
  EXPECT_EQ(ends_moved, 0u);
}

using flat_detail::V2;

// Flat rings around holes (3D: radius 10 mm to `outer`, 64 sectors, rings as square as the
// sectors) side by side in one band, each hole's rim a rim and its outer circle an end, and a flat
// sheet mapped as it is (the band's area scale stays near 1). `mapped(r)`: the map radius of 3D
// radius r.
struct RingBand {
  static constexpr int kSectors = 64;
  flat_detail::SegmentWork w;
  std::vector<char> ends, degenerate;
  std::vector<std::vector<int>> vf;
  std::vector<std::vector<int>> rim;  // per ring: its rim's vertices
  void add_ring(double x, double outer, const std::function<V2(double, double)>& mapped) {
    std::vector<double> radius{10};
    while (radius.back() < outer) radius.push_back(std::min(outer, radius.back() * (1 + 2 * M_PI / kSectors)));
    const int base = int(w.ann.p.size()), rings = int(radius.size());
    rim.emplace_back();
    for (int k = 0; k < rings; ++k)
      for (int j = 0; j < kSectors; ++j) {
        const double a = 2 * M_PI * j / kSectors;
        w.ann.p.emplace_back(x + radius[k] * std::cos(a), radius[k] * std::sin(a), 0.0);
        w.emb.pos.push_back(V2(x, 0) + mapped(radius[k], a));
        ends.push_back(k == rings - 1);
        if (k == 0) rim.back().push_back(int(w.ann.p.size()) - 1);
      }
    const auto id = [&](int k, int j) { return base + k * kSectors + (j % kSectors); };
    for (int k = 0; k + 1 < rings; ++k)
      for (int j = 0; j < kSectors; ++j)
        w.ann.t.push_back({id(k, j), id(k + 1, j + 1), id(k, j + 1)}), w.ann.t.push_back({id(k, j), id(k + 1, j), id(k + 1, j + 1)});
  }
  void add_sheet(double x, double side, int n) {  // its border is an end
    const int base = int(w.ann.p.size());
    for (int i = 0; i <= n; ++i)
      for (int j = 0; j <= n; ++j) {
        w.ann.p.emplace_back(x + side * i / n, side * j / n, 0.0), w.emb.pos.emplace_back(x + side * i / n, side * j / n);
        ends.push_back(i == 0 || j == 0 || i == n || j == n);
      }
    const auto id = [&](int i, int j) { return base + i * (n + 1) + j; };
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        w.ann.t.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)}), w.ann.t.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
  }
  void finish() {
    w.emb.dy.assign(w.ann.t.size(), {0.0, 0.0, 0.0});
    w.emb.period = 1e6;  // not periodic
    degenerate.assign(w.ann.t.size(), 0);
    vf = flat_detail::vertex_faces(w.ann);
  }
  // Wall (3D mm^2) of ring `i`'s faces (ring i's faces: those with a vertex within 40 mm of its centre
  // x = 100 i) shown below ratio 0.1 at the map's area scale.
  double hidden(int i) const {
    double a2 = 0, a3 = 0, out = 0;
    for (std::size_t f = 0; f < w.ann.t.size(); ++f) a2 += w.emb.area2(w.ann, int(f)), a3 += flat_detail::face_area_3d(w.ann, int(f));
    for (std::size_t f = 0; f < w.ann.t.size(); ++f) {
      const double r3 = flat_detail::face_area_3d(w.ann, int(f));
      if (std::abs(w.ann.p[w.ann.t[f][0]].x() - 100 * i) < 40 && w.emb.area2(w.ann, int(f)) * a3 / a2 < 0.1 * r3) out += r3;
    }
    return out;
  }
};

// Two rims freed in one band's local passes: ring 0's hole (map radius 9 for 3D 10) has room for
// the crushed strip along it; ring 1's hole is pinched to a point in the map between two lobes, the
// wall above and below it short of area, so its rim's two sides pass each other there (a fold at
// a rim vertex). The outer circles (ends) sit close, so a held rim leaves ring 0's strip crushed.
// Ring 1's rim is held and its pieces restored and corrected again (its rim back where it was, its
// crushed wall still reduced, no rim crossing), while ring 0 keeps its opened strip (hidden < 1 %
// of before; main's rule restored both rings and held both rims: ring 0's strip then stays above
// half of what it hid, as the run with both rims held shows); no face folds.
TEST(FlattenFork, OnlyTheRimThatCrossesIsHeldAgain) {
  RingBand band;
  band.add_ring(0, 14, [](double r, double a) -> V2 {  // the strip out to 3D radius 13.7 crushed radially (x 0.05)
    return (r < 13.7 ? 9 + 0.05 * (r - 10) : 9.185 + (r - 13.7)) * V2(std::cos(a), std::sin(a));
  });
  band.add_ring(100, 14, [](double r, double a) -> V2 {  // a hole pinched to a point at x = 0 (two lobes), the wall
    const double t = (r - 10) / 4, c = std::max(0.0, std::sin(a));  // above crushed, the end 2 mm above and below
    const double u = (1 - c) * t + c * (t < 0.9 ? 0.02 * t : 0.018 + (t - 0.9) / 0.1 * 0.982);
    const V2 rim(9 * std::cos(a), 0.3 * std::sin(a) * std::abs(std::cos(a))), end(9.5 * std::cos(a), 2 * std::sin(a));
    return rim + u * (end - rim);
  });
  band.add_sheet(200, 100, 20);
  band.finish();
  for (std::size_t f = 0; f < band.w.ann.t.size(); ++f) ASSERT_GT(band.w.emb.area2(band.w.ann, int(f)), 0.0);
  const auto rims = flat_detail::cut_rims(band.w.ann, flat_detail::build_edges(band.w.ann.t), band.ends);
  ASSERT_EQ(rims.loops.size(), 2u);
  ASSERT_EQ(flat_detail::rim_crossings(band.w, rims), (std::vector<std::size_t>{0, 0}));
  const double before0 = band.hidden(0), before1 = band.hidden(1);
  ASSERT_GT(before0, 100.0);
  ASSERT_GT(before1, 100.0);
  RingBand held = band;
  flat_detail::local_passes_freeing(held.w, rims, {0, 0}, held.vf, held.ends, held.degenerate, FlattenOptions{}, false);
  EXPECT_GT(held.hidden(0), 0.5 * before0);
  const RingBand start = band;
  flat_detail::local_passes_freeing(band.w, rims, {1, 1}, band.vf, band.ends, band.degenerate, FlattenOptions{}, false);
  EXPECT_LT(band.hidden(0), 0.01 * before0);
  EXPECT_LT(band.hidden(1), before1);
  EXPECT_EQ(flat_detail::rim_crossings(band.w, rims), (std::vector<std::size_t>{0, 0}));
  std::size_t rim0_moved = 0, rim1_moved = 0;
  for (int v : band.rim[0]) rim0_moved += band.w.emb.pos[std::size_t(v)] != start.w.emb.pos[std::size_t(v)];
  for (int v : band.rim[1]) rim1_moved += band.w.emb.pos[std::size_t(v)] != start.w.emb.pos[std::size_t(v)];
  EXPECT_EQ(rim0_moved, band.rim[0].size());
  EXPECT_EQ(rim1_moved, 0u);
  for (std::size_t f = 0; f < band.w.ann.t.size(); ++f) EXPECT_GT(band.w.emb.area2(band.w.ann, int(f)), 0.0);
}

// The wall's mean area ratio (at the band's area scale) over the faces whose 3D corners all lie
// within `radius` of the origin.
double mean_ratio_within(const flat_detail::SegmentWork& w, double radius) {
  const double scale = flat_detail::band_area_scale(w, nullptr);
  double a2 = 0, a3 = 0;
  for (std::size_t f = 0; f < w.ann.t.size(); ++f) {
    const auto& t = w.ann.t[f];
    if (std::max({w.ann.p[t[0]].norm(), w.ann.p[t[1]].norm(), w.ann.p[t[2]].norm()}) > radius) continue;
    a2 += scale * w.emb.area2(w.ann, int(f)), a3 += flat_detail::face_area_3d(w.ann, int(f));
  }
  return a2 / a3;
}

// A limb-sized branch's rim held short: a flat ring (3D radius 10 to 45 mm, the band's period 100 mm)
// whose map keeps the hole's rim at 0.4 x its 3D length and the wall out to 3D radius 20 shrunk
// alike (x 0.4 both ways: area ratio ~0.16, what the conformal map leaves beside such a rim), the
// rest stretched out to the outer circle (an end). widen_short_rims() moves the rim as one curve
// (every rim vertex scaled about one centre by one factor > 1: no crossing, its shape kept), folds no
// face, moves no end, and the wall beside the rim ends at a mean ratio >= 0.3 (area_ratio_low 0.4
// is its aim); held (main's rule), the local passes leave that wall below 0.2. local_area_passes()
// widens it alike first and holds it there.
TEST(FlattenFork, ShortRimGivesWayAsOneCurveAndTheWallBesideItOpens) {
  RingBand band;
  band.add_ring(0, 45, [](double r, double a) -> V2 {
    return (r < 20 ? 0.4 * r : 8 + (r - 20) * (45 - 8) / 25) * V2(std::cos(a), std::sin(a));
  });
  band.finish();
  band.w.emb.period = 100;
  const auto E = flat_detail::build_edges(band.w.ann.t);
  const auto rims = flat_detail::cut_rims(band.w.ann, E, band.ends);
  ASSERT_EQ(rims.loops.size(), 1u);
  const double held_before = mean_ratio_within(band.w, 20);
  ASSERT_LT(held_before, 0.2);
  RingBand held = band;
  flat_detail::local_passes_freeing(held.w, rims, {0}, held.vf, held.ends, held.degenerate, FlattenOptions{}, false);
  EXPECT_LT(mean_ratio_within(held.w, 20), 0.2);
  const RingBand start = band;
  ASSERT_EQ(flat_detail::widen_short_rims(band.w, rims, {0}, band.ends, FlattenOptions{}), std::vector<char>{1});
  const auto at = [](const RingBand& b, int i) { return b.w.emb.pos[std::size_t(b.rim[0][std::size_t(i)])]; };
  const double s = (at(band, 0) - at(band, 32)).norm() / (at(start, 0) - at(start, 32)).norm();
  EXPECT_GT(s, 1.5);
  for (int i = 0; i < RingBand::kSectors; ++i)  // one similarity: every chord scaled by s
    for (int j : {i + 1, i + 7, i + 29})
      EXPECT_NEAR((at(band, i) - at(band, j % 64)).norm(), s * (at(start, i) - at(start, j % 64)).norm(), 1e-9 * s);
  EXPECT_EQ(flat_detail::rim_crossings(band.w, rims), std::vector<std::size_t>{0});
  for (std::size_t v = 0; v < band.ends.size(); ++v)
    if (band.ends[v]) EXPECT_EQ(band.w.emb.pos[v], start.w.emb.pos[v]);
  for (std::size_t f = 0; f < band.w.ann.t.size(); ++f) EXPECT_GT(band.w.emb.area2(band.w.ann, int(f)), 0.0);
  EXPECT_GE(mean_ratio_within(band.w, 20), 0.3);
  RingBand passes = start;  // the local passes widen it alike and hold it there
  std::vector<char> fixed = passes.ends;
  for (int v : passes.rim[0]) fixed[std::size_t(v)] = 1;
  flat_detail::local_area_passes(passes.w, E, passes.vf, fixed, passes.ends, passes.degenerate, FlattenOptions{}, false, false);
  for (int i = 0; i < RingBand::kSectors; ++i) EXPECT_EQ(at(passes, i), at(band, i));
  EXPECT_GE(mean_ratio_within(passes.w, 20), 0.3);
}

}  // namespace
}  // namespace cf
