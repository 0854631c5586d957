// A fork of the lumen (a limb of the tube's own girth, cut off as a side branch): the colon band
// keeps a hole as wide as itself, and the strip of wall along that hole's rim is shown.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

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
  std::size_t differ = 0;
  for (std::size_t i = 0; i < f.uv.size(); ++i) differ += one.uv[i][0] != f.uv[i][0] || one.uv[i][1] != f.uv[i][1];
  EXPECT_EQ(differ, 0u);
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
  flat_detail::local_area_passes(rim.w, flat_detail::build_edges(rim.w.ann.t), rim.vf, rim.fixed, rim.ends, rim.degenerate, FlattenOptions{}, false);
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

}  // namespace
}  // namespace cf
