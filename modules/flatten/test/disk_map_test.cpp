// The free-boundary disk map (src/disk_map.cpp): a disk-shaped piece mapped as itself (LSCM, then the
// area correction with its boundary free), kept only when injective.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "../src/band_faces.h"
#include "../src/branch_bands.h"
#include "../src/disk_map.h"
#include "colonflat/core/threads.h"
#include "squeezed_grid.h"
#include "strip_shapes.h"

namespace cf {
namespace {

using flat_detail::V2;
using flat_detail::V3;

using test_shapes::stadium;
using test_shapes::strip;

// The strip(n, n) grid's vertices moved by `place` (x, y in [0, 1] -> 3D).
template <class Place>
flat_detail::Surface bent_grid(int n, Place place) {
  flat_detail::Surface s = strip(n, n);
  for (V3& p : s.p) p = place(p.x() / (n - 1), p.y() / (n - 1));
  return s;
}

// A hemisphere of radius 20 mm, open at its equator (a disk): the grid's square onto the disk of
// radius 1 (radial stretch), then lifted onto the sphere.
flat_detail::Surface hemisphere() {
  return bent_grid(41, [](double x, double y) {
    const double a = 2 * x - 1, b = 2 * y - 1, r = std::max(std::abs(a), std::abs(b));
    const double len = std::hypot(a, b), rho = len > 0 ? r / len : 0.0;
    const double theta = 0.5 * M_PI * rho * len, phi = std::atan2(b, a);
    return V3(20 * std::sin(theta) * std::cos(phi), 20 * std::sin(theta) * std::sin(phi), 20 * std::cos(theta));
  });
}

// A finger: a hemisphere of radius 8 mm on a tube of the same radius, 16 mm long, open at the tube's
// end (a disk whose conformal map spreads the area ratios ~ 1 : 50: the area correction works on it).
flat_detail::Surface finger() {
  return bent_grid(41, [](double x, double y) {
    const double a = 2 * x - 1, b = 2 * y - 1, r = std::max(std::abs(a), std::abs(b));
    const double len = std::hypot(a, b), phi = std::atan2(b, a), cap = 0.5 * M_PI * 8;
    const double arc = r * (cap + 16);  // arc length from the tip
    if (arc <= cap) return V3(8 * std::sin(arc / 8) * std::cos(phi), 8 * std::sin(arc / 8) * std::sin(phi), 8 * std::cos(arc / 8));
    return V3(8 * std::cos(phi), 8 * std::sin(phi), -(arc - cap));
    (void)len;
  });
}

// What disk_band made of a surface: the band and the result.
struct DiskRun {
  flat_detail::SegmentWork w;
  flat_detail::DiskMapResult r;
};
DiskRun run_disk(const flat_detail::Surface& s, const FlattenOptions& o = {}) {
  DiskRun d;
  d.w.ann = s;
  flat_detail::Prepared p{flat_detail::build_edges(s.t), {}, {}, {}};
  flat_detail::prepare_faces(d.w, p);
  d.r = flat_detail::disk_band(d.w, p, o);
  return d;
}

// Brute force: the share of the wall at area ratio >= min_ratio (2D / 3D area), none folded.
double shown_share(const DiskRun& d, double min_ratio, std::size_t& flipped) {
  double a3 = 0, shown = 0;
  flipped = 0;
  for (std::size_t f = 0; f < d.w.ann.t.size(); ++f) {
    const double A3 = flat_detail::face_area_3d(d.w.ann, int(f)), A2 = d.w.emb.area2(d.w.ann, int(f));
    a3 += A3, shown += A2 >= min_ratio * A3 ? A3 : 0.0, flipped += A2 <= 0;
  }
  return shown / a3;
}

// A flat 12 x 120 mm stadium (a strip of wall a tube map crushes: 14.6 % shown from a tip cap, see
// PatchSlit) is shown whole by the disk map: every face at ratio ~1, none folded, the band's box about
// 120 x 12 mm and holding every vertex.
TEST(DiskMap, FlatStadiumIsShownWhole) {
  const DiskRun d = run_disk(stadium(121));
  ASSERT_TRUE(d.r.ok) << d.r.why;
  std::size_t flipped = 0;
  EXPECT_GE(shown_share(d, 0.9, flipped), 0.995);
  EXPECT_EQ(flipped, 0u);
  EXPECT_NEAR(std::max(d.w.seg.length, d.w.seg.period), 120.0, 1.5);
  EXPECT_NEAR(std::min(d.w.seg.length, d.w.seg.period), 12.0, 1.5);
  for (const V2& q : d.w.emb.pos) {
    EXPECT_GE(q.x(), 0.0);
    EXPECT_LE(q.x(), d.w.seg.length);
    EXPECT_GE(q.y(), 0.0);
    EXPECT_LT(q.y(), d.w.seg.period);
  }
  EXPECT_EQ(d.w.seg.map, "disk");
}

// The map is at the area-preserving scale: the 2D areas sum to the 3D area (the curved hemisphere,
// whose conformal map alone spreads the ratios 1 : 4), and >= 99.5 % is shown, none folded.
TEST(DiskMap, HemisphereIsShownAtTheAreaPreservingScale) {
  const DiskRun d = run_disk(hemisphere());
  ASSERT_TRUE(d.r.ok) << d.r.why;
  double a2 = 0;
  for (std::size_t f = 0; f < d.w.ann.t.size(); ++f) a2 += d.w.emb.area2(d.w.ann, int(f));
  EXPECT_NEAR(a2 / d.w.seg.area_3d, 1.0, 0.02);
  std::size_t flipped = 0;
  EXPECT_GE(shown_share(d, 0.1, flipped), 0.995);
  EXPECT_EQ(flipped, 0u);
}

// A helical ramp between radii 20 and 30 mm turning 1.3 times (almost flat: 2 mm rise per turn) has a
// conformal map that is an annular sector of ~470 degrees: it overlaps itself, and the disk map is
// refused (the caller keeps the tube map).
TEST(DiskMap, RampThatWouldOverlapIsRefused) {
  const flat_detail::Surface ramp = bent_grid(61, [](double x, double y) {
    const double a = 1.3 * 2 * M_PI * x, r = 20 + 10 * y;
    return V3(r * std::cos(a), r * std::sin(a), 2 * a / (2 * M_PI));
  });
  const DiskRun d = run_disk(ramp);
  EXPECT_FALSE(d.r.ok);
  EXPECT_STREQ(d.r.why, "the conformal map overlaps itself");
  // The same ramp turning 0.6 times does not overlap: mapped.
  const DiskRun part = run_disk(bent_grid(61, [](double x, double y) {
    const double a = 0.6 * 2 * M_PI * x, r = 20 + 10 * y;
    return V3(r * std::cos(a), r * std::sin(a), 2 * a / (2 * M_PI));
  }));
  EXPECT_TRUE(part.r.ok) << part.r.why;
}

// A fan of 7 faces around a centre vertex, each 60 degrees (all positive), spans 420 degrees in the
// plane: its boundary crosses itself, so it is not injective; the first 5 faces (300 degrees) are;
// one face turned over is not either.
TEST(DiskMap, FanPastAFullTurnIsNotInjective) {
  auto fan = [](int faces) {
    flat_detail::Surface s;
    flat_detail::Embedding emb;
    s.p.emplace_back(0, 0, 0), emb.pos.emplace_back(0, 0);
    for (int i = 0; i <= faces; ++i) {
      const double a = i * M_PI / 3;
      s.p.emplace_back(10 * std::cos(a), 10 * std::sin(a), a), emb.pos.emplace_back(10 * std::cos(a), 10 * std::sin(a));
      if (i > 0) s.t.push_back({0, i, i + 1});
    }
    emb.dy.assign(s.t.size(), {0.0, 0.0, 0.0});
    emb.period = 100;
    return std::make_pair(s, emb);
  };
  for (int faces : {5, 7}) {
    auto [s, emb] = fan(faces);
    const std::vector<char> deg(s.t.size(), 0);
    EXPECT_EQ(flat_detail::injective_disk_map(s, flat_detail::build_edges(s.t), emb, deg), faces == 5) << faces;
  }
  auto [s, emb] = fan(5);
  emb.pos[1] = V2(5, 12);  // the first face turned over (its corners now clockwise)
  EXPECT_FALSE(flat_detail::injective_disk_map(s, flat_detail::build_edges(s.t), emb, std::vector<char>(s.t.size(), 0)));
}

// 1 and 2 threads give the disk map bit for bit (the finger: its area correction runs).
TEST(DiskMap, SameMapForOneAndTwoThreads) {
  set_thread_count(1);
  const DiskRun one = run_disk(finger());
  set_thread_count(2);
  const DiskRun two = run_disk(finger());
  set_thread_count(0);
  ASSERT_TRUE(one.r.ok && two.r.ok);
  ASSERT_EQ(one.w.emb.pos.size(), two.w.emb.pos.size());
  for (std::size_t v = 0; v < one.w.emb.pos.size(); ++v) EXPECT_EQ(one.w.emb.pos[v], two.w.emb.pos[v]) << v;
  EXPECT_GT(one.r.corrected_iterations + int(one.r.balanced_vertices), 0);  // the correction ran
}

// A tube map (one band) that shows `shown` of the piece's wall `wall` (mm^2), area p05 0.
std::vector<flat_detail::SegmentWork> tube_showing(double shown, double wall) {
  std::vector<flat_detail::SegmentWork> tube(1);
  tube[0].seg.coverage.wall_area_mm2 = wall;
  tube[0].seg.coverage.shown_area_mm2 = shown;
  tube[0].seg.stats.area_p05 = 0.0;
  tube[0].seg.map = "area-balanced";
  return tube;
}

// tube_or_disk tries a disk piece's disk map only up to kDiskMapMaxFaces faces: the 12 x 120 mm
// stadium (2 8xx faces) whose tube map shows half of it gets its disk map (made, and kept: it shows
// >= 99.5 %); a 12 x 1 800 mm stadium (over 40 000 faces) with the same tube map keeps the tube map
// and its disk map is never made (measured: no piece above 8 532 faces won on the three patched
// rows, the 285 943-face one took 14.8 CPU s to show 54 %).
TEST(DiskMap, OnlyPiecesUpToTheSizeLimitAreDiskMapped) {
  for (int nx : {121, 1801}) {
    flat_detail::BranchPiece piece;
    piece.surface = stadium(nx);
    const bool small = piece.surface.t.size() <= flat_detail::kDiskMapMaxFaces;
    ASSERT_EQ(small, nx == 121) << piece.surface.t.size();
    const double wall = flat_detail::surface_area(piece.surface);
    int made = 0;
    const flat_detail::FlattenDisk disk = [&](const flat_detail::Surface& d) {
      ++made;
      return flat_detail::flatten_disk(d, 0, 1.0, FlattenOptions{});
    };
    const auto works = flat_detail::tube_or_disk(piece, tube_showing(0.5 * wall, wall), disk, 1);
    ASSERT_EQ(works.size(), 1u);
    EXPECT_EQ(made, small ? 1 : 0) << nx;
    EXPECT_EQ(works[0].seg.map, small ? "disk" : "area-balanced") << nx;
    if (small) EXPECT_GE(works[0].seg.coverage.shown_area_mm2, 0.995 * wall);
  }
}

}  // namespace
}  // namespace cf
