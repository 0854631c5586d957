// Side branches (branches.cpp): a pouch the conformal map collapses is cut at its neck and shown
// as a band of its own; nothing of the kind on a plain tube; the fields survive the flat file.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "../src/branch_ends.h"
#include "../src/flatten_internal.h"
#include "colonflat/core/error.h"
#include "colonflat/core/mesh_io.h"
#include "colonflat/core/synthetic.h"
#include "colonflat/core/threads.h"
#include "squeezed_grid.h"
#include "colonflat/flatten/flat_artifact.h"
#include "colonflat/flatten/flatten.h"
#include "colonflat/flatten/flatten_stage.h"
#include "colonflat/flatten/synthetic_colon.h"
#include "colonflat/testing/stage_command.h"
#include "colonflat/testing/temp_dir.h"
#include "flatten_shapes.h"

namespace cf {
namespace {

double wall_area(const TriangleList& t) {
  double a = 0;
  for (const auto& tr : t.triangles) {
    const Eigen::Vector3d p0(t.points[tr[0]].data()), p1(t.points[tr[1]].data()), p2(t.points[tr[2]].data());
    a += 0.5 * (p1 - p0).cross(p2 - p0).norm();
  }
  return a;
}

// A pouch (22 mm sphere) behind a 3 mm neck: a second band holding lumen, hanging from the colon
// band at the neck (LPS ~ (120, 12..32, 0), neck length ~ 2 pi 3 mm), and the whole wall shown;
// one edge graph built per band (the opened annulus and the colon left after the cut reuse it).
TEST(FlattenBranches, PouchBehindNarrowNeckIsABandOfItsOwn) {
  const TriangleList mesh = test_shapes::pouch_behind_neck(3.0);
  const std::size_t built = flat_detail::build_edges_count();
  const FlatMap f = flatten_colon(mesh);
  ASSERT_EQ(f.segments.size(), 2u);
  EXPECT_EQ(flat_detail::build_edges_count() - built, 2u);
  const FlatSegment& colon = f.segments[0];
  const FlatSegment& b = f.segments[1];
  EXPECT_EQ(colon.kind, "colon");
  EXPECT_EQ(b.kind, "branch");
  EXPECT_EQ(b.parent, colon.id);
  EXPECT_EQ(b.x0_end, "neck");
  EXPECT_EQ(b.holds, "lumen");
  EXPECT_NEAR(b.attach_lps[0], 120.0, 6.0);
  EXPECT_GT(b.attach_lps[1], 8.0);
  EXPECT_LT(b.attach_lps[1], 40.0);
  EXPECT_GT(b.neck_mm, 0.5 * 2 * M_PI * 3.0);
  EXPECT_LT(b.neck_mm, 3.0 * 2 * M_PI * 3.0);
  EXPECT_GT(b.area_3d, 0.8 * 4 * M_PI * 22 * 22);  // the sphere's wall is in the branch band
  EXPECT_NEAR(b.attach_mm, std::abs(120.0 - colon.end_a[0]), 10.0);  // centreline mm from the band's x0 end
  EXPECT_GE(f.coverage.fraction, 0.995);
  EXPECT_EQ(f.stats.flipped, 0u);
  // Every bit of wall is accounted for once: the bands' walls plus the end caps = the surface.
  EXPECT_NEAR(f.coverage.wall_area_mm2 + f.coverage.end_cap_area_mm2, wall_area(mesh), 1e-6 * wall_area(mesh));
}

// With branches off (--branch-min-area 0) the same pouch stays in the colon band, collapsed:
// it is reported as wall not shown, at its place.
TEST(FlattenBranches, WithoutBranchesThePouchIsNotShownAndLocated) {
  FlattenOptions o;
  o.branch_min_area = 0;
  const FlatMap f = flatten_colon(test_shapes::pouch_behind_neck(3.0), o);
  ASSERT_EQ(f.segments.size(), 1u);
  EXPECT_LT(f.coverage.fraction, 0.9);
  ASSERT_FALSE(f.coverage.not_shown.empty());
  EXPECT_NEAR(f.coverage.not_shown[0].centroid_lps_mm[0], 120.0, 10.0);
  EXPECT_GT(f.coverage.not_shown[0].centroid_lps_mm[1], 30.0);
}

// A 40 mm strand stump (tissue, 1 mm radius) is crushed by the conformal map below what the map
// resolves: it is cut at its base and shown as a band of its own that says it holds tissue, and
// the colon band keeps every face in its map (none left out, none folded), its whole wall shown.
TEST(FlattenBranches, CrushedTissueStrandIsABandOfItsOwn) {
  const FlatMap f = flatten_colon(test_shapes::tube_and_strand(40.0));
  const FlatSegment& colon = f.segments[0];
  EXPECT_EQ(colon.crowded_faces, 0u);
  EXPECT_EQ(colon.inverted_faces, 0u);
  EXPECT_EQ(colon.stats.flipped, 0u);
  EXPECT_GE(colon.coverage.fraction, 0.995);
  EXPECT_LE(colon.stats.qc_mean, 1.5);
  ASSERT_EQ(f.segments.size(), 2u);
  const FlatSegment& b = f.segments[1];
  EXPECT_EQ(b.kind, "branch");
  EXPECT_EQ(b.holds, "tissue");
  EXPECT_NEAR(b.attach_lps[0], 104.0, 6.0);  // its neck is at the strand's base on the wall (z = -12)
  EXPECT_LT(b.attach_lps[2], -8.0);
  EXPECT_GT(b.area_3d, 0.8 * 2 * M_PI * 1.0 * 30.0);
  EXPECT_GE(b.coverage.fraction, 0.9);
  EXPECT_GE(f.coverage.fraction, 0.995);
}

// The same strand kept on the colon band (--branch-min-area 0) and no area correction (which moves
// the strand's crushed tip back into the map, area_correct_test.cpp): its faces are left out of the
// map, and the stage's segment line says how many and how many of them fold over ("flipped" counts
// only faces in the map), as the flat file's segment fields do.
TEST(FlattenBranches, StrandLeftOnTheBandIsCountedLeftOut) {
  testing::TempDir tmp;
  write_mesh(synthetic::to_mesh(test_shapes::tube_and_strand(40.0)), tmp / "in.vtp");
  const auto r = testing::run_stage_command(make_flatten_stage, {tmp.str("in.vtp"), "-o", tmp.str("flat.vtp"), "--branch-min-area",
                                                                 "0", "--area-correction-iterations", "0"});
  ASSERT_EQ(r.code, 0) << r.err;
  const FlatMap g = read_flat(tmp / "flat.vtp");
  ASSERT_EQ(g.segments.size(), 1u);
  EXPECT_GT(g.segments[0].crowded_faces, 20u);
  EXPECT_LT(g.coverage.fraction, 0.995);
  const std::string said = "left out of the map " + std::to_string(g.segments[0].crowded_faces) + " faces (" +
                           std::to_string(g.segments[0].inverted_faces) + " folded over)";
  EXPECT_NE((r.out + r.err).find(said), std::string::npos) << r.out << r.err;
}

// A polyp on a thin stalk is collapsed like a pouch but is tissue, not lumen: it stays on the
// colon band (no side branch), where the image and the polyp detection look for it.
TEST(FlattenBranches, PolypOnAStalkStaysOnTheColonBand) {
  const FlatMap f = flatten_colon(test_shapes::stalked_polyp());
  ASSERT_EQ(f.segments.size(), 1u);
  EXPECT_EQ(f.segments[0].kind, "colon");
  bool head_on_band = false;  // a flat vertex on top of the head (z > 2 mm, near x = 100)
  for (std::size_t i = 0; i < f.position.size(); ++i)
    head_on_band = head_on_band || (std::abs(f.position[i][0] - 100) < 4 && f.position[i][2] > 2);
  EXPECT_TRUE(head_on_band);
}

// A plain folded colon tube has no side branch (no false cut) and keeps its whole wall.
TEST(FlattenBranches, PlainFoldedTubeHasNoBranch) {
  synthetic::ColonOptions o;
  o.length = 300;
  o.radius = 15;
  o.spacing = 1.5;
  o.fold_height = 4;
  const FlatMap f = flatten_colon(synthetic::colon(o).mesh);
  ASSERT_EQ(f.segments.size(), 1u);
  EXPECT_EQ(f.segments[0].kind, "colon");
  EXPECT_GE(f.coverage.fraction, 0.995);
}

// The branch fields (kind, parent, attachment, neck, what it holds) survive the flat .vtp round trip.
TEST(FlattenBranches, BranchFieldsSurviveTheFlatFile) {
  testing::TempDir tmp;
  const FlatMap f = flatten_colon(test_shapes::pouch_behind_neck(3.0));
  ASSERT_EQ(f.segments.size(), 2u);
  write_flat(f, tmp / "flat.vtp");
  const FlatMap g = read_flat(tmp / "flat.vtp");
  ASSERT_EQ(g.segments.size(), 2u);
  EXPECT_EQ(g.segments[1].kind, "branch");
  EXPECT_EQ(g.segments[1].parent, f.segments[1].parent);
  EXPECT_DOUBLE_EQ(g.segments[1].attach_mm, f.segments[1].attach_mm);
  EXPECT_EQ(g.segments[1].attach_lps, f.segments[1].attach_lps);
  EXPECT_DOUBLE_EQ(g.segments[1].neck_mm, f.segments[1].neck_mm);
  EXPECT_EQ(g.segments[1].holds, "lumen");
  EXPECT_EQ(g.segments[0].kind, "colon");
}

// A strand stump's band says "tissue" in the flat file's FlatSegments and in the stage's report
// (segments[1].holds), which render reads to caption it.
TEST(FlattenBranches, TissueBandSaysSoInTheFlatFileAndReport) {
  testing::TempDir tmp;
  write_mesh(synthetic::to_mesh(test_shapes::tube_and_strand(40.0)), tmp / "in.vtp");
  const auto r = testing::run_stage_command(make_flatten_stage, {tmp.str("in.vtp"), "-o", tmp.str("flat.vtp"),
                                                                 "--report", tmp.str("report.json")});
  ASSERT_EQ(r.code, 0) << r.err;
  const FlatMap g = read_flat(tmp / "flat.vtp");
  ASSERT_EQ(g.segments.size(), 2u);
  EXPECT_EQ(g.segments[1].holds, "tissue");
  std::ifstream in(tmp / "report.json");
  const nlohmann::json segs = nlohmann::json::parse(in)["result"]["segments"];
  ASSERT_EQ(segs.size(), 2u);
  EXPECT_EQ(segs[1].value("kind", ""), "branch");
  EXPECT_EQ(segs[1].value("holds", ""), "tissue");
  EXPECT_FALSE(segs[0].contains("holds"));  // the colon band is no branch
}

// The faces, flat embedding and edges of a plane grid of spacing h over [0, length] x [0, width] mm,
// row by row, two triangles per cell; `place(q)` adds grid point q's 3D point and map point.
template <class Place>
void plane_grid(double h, double length, double width, Place place, flat_detail::Surface& s,
                flat_detail::Embedding& emb, flat_detail::Edges& E) {
  const int nx = int(length / h) + 1, ny = int(width / h) + 1;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) place(flat_detail::V2(i * h, j * h));
  test_shapes::grid_triangles(nx, ny, s.t);
  emb.dy.assign(s.t.size(), {0.0, 0.0, 0.0});
  emb.period = 1000;
  E = flat_detail::build_edges(s.t);
}

// find_branches on a test plane g (lumen sign +1, clusters of at least min_area_mm2) with `threads`
// worker threads, the default count restored after; `search` receives its counters.
template <class Plane>
std::vector<flat_detail::BranchCut> branches_on_threads(const Plane& g, int threads, double min_area_mm2,
                                                        flat_detail::BranchSearch& search) {
  set_thread_count(threads);
  std::vector<flat_detail::BranchCut> cuts = flat_detail::find_branches(g.s, g.E, g.emb, g.kLength, 1.0, min_area_mm2, &search);
  set_thread_count(0);
  return cuts;
}

// A plane (0..60 x 0..30 mm, 0.25 mm grid, z = 0) with pouches: inside the disk of radius rn around
// (cx, cy) the grid rises as a cylinder of radius rn (height hc) topped by a sphere of radius rs (an
// overhang: the rim is shortest, 2 pi rn, at the neck), and the map squeezes that disk to 1e-3 of
// its size around its centre (what the conformal map does to a pouch); elsewhere the map is the grid.
struct PouchesOnAPlane {
  struct Pouch {
    double cx, cy, rn, rs, hc;
    double area() const {  // analytic wall area: the sphere above the neck circle and the cylinder
      return 2 * M_PI * rs * rs * (1 + std::sqrt(1 - rn * rn / (rs * rs))) + 2 * M_PI * rn * hc;
    }
  };
  static constexpr double kH = 0.25, kSqueeze = 1e-3, kLength = 60, kWidth = 30;
  std::vector<Pouch> pouches;
  flat_detail::Surface s;
  flat_detail::Embedding emb;
  flat_detail::Edges E;

  explicit PouchesOnAPlane(std::vector<Pouch> ps) : pouches(std::move(ps)) {
    plane_grid(kH, kLength, kWidth, [this](const flat_detail::V2& q) { place(q); }, s, emb, E);
  }
  // The pouch whose disk holds grid point q (-1: none).
  int pouch_of(const flat_detail::V2& q) const {
    for (std::size_t k = 0; k < pouches.size(); ++k)
      if ((q - flat_detail::V2(pouches[k].cx, pouches[k].cy)).norm() < pouches[k].rn) return int(k);
    return -1;
  }
  // The pouch all three corners of face f are in (-1: none); `margin` mm widens its disk.
  int pouch_of_face(int f, double margin = 0) const {
    for (std::size_t k = 0; k < pouches.size(); ++k) {
      const flat_detail::V2 c(pouches[k].cx, pouches[k].cy);
      bool all = true;
      for (int v : s.t[f]) all = all && (grid_of(v) - c).norm() < pouches[k].rn + margin;
      if (all) return int(k);
    }
    return -1;
  }
  flat_detail::V2 grid_of(int v) const {
    const int nx = int(kLength / kH) + 1;
    return flat_detail::V2((v % nx) * kH, (v / nx) * kH);
  }

 private:
  void place(const flat_detail::V2& q) {
    const int k = pouch_of(q);
    if (k < 0) {
      s.p.push_back(flat_detail::V3(q.x(), q.y(), 0));
      emb.pos.push_back(q);
      return;
    }
    const Pouch& o = pouches[std::size_t(k)];
    const flat_detail::V2 c(o.cx, o.cy), off = q - c;
    const double rho = off.norm(), phi_max = M_PI - std::asin(o.rn / o.rs);
    const double a = rho / o.rn * (o.rs * phi_max + o.hc);  // arc length from the top along the profile
    const double zc = o.hc + o.rs * std::sqrt(1 - o.rn * o.rn / (o.rs * o.rs));
    const double g = a <= o.rs * phi_max ? o.rs * std::sin(a / o.rs) : o.rn;
    const double z = a <= o.rs * phi_max ? zc + o.rs * std::cos(a / o.rs) : o.hc - (a - o.rs * phi_max);
    const flat_detail::V2 xy = rho > 0 ? flat_detail::V2(c + off / rho * g) : c;
    s.p.push_back(flat_detail::V3(xy.x(), xy.y(), z));
    emb.pos.push_back(c + kSqueeze * off);
  }
};

// Two pouches (a larger, then a smaller) are each cut at their neck: all their faces and of the
// plane only a ring one sampled radius wide (<= 2 grid steps), about their analytic wall area and neck length, disjoint, largest first; both clusters are
// searched side by side (none again: neither search reaches the other pouch), and one and two
// threads give the same cuts, face for face.
TEST(FlattenBranches, PouchClustersAreSearchedSideBySideAndCutAtTheirNecks) {
  const PouchesOnAPlane g({{15, 15, 4, 8, 3}, {45, 15, 3, 6, 3}});
  std::vector<std::vector<flat_detail::BranchCut>> runs;
  for (int threads : {2, 1}) {
    flat_detail::BranchSearch search;
    runs.push_back(branches_on_threads(g, threads, 50.0, search));
    EXPECT_EQ(search.clusters, 2u);
    EXPECT_EQ(search.searched_again, 0u);
  }
  const auto& cuts = runs[0];
  ASSERT_EQ(cuts.size(), 2u);
  std::vector<int> owner(g.s.t.size(), -1);
  for (std::size_t k = 0; k < 2; ++k) {
    std::size_t inside = 0, near = 0, pouch_faces = 0;
    for (int f : cuts[k].faces) {
      EXPECT_EQ(owner[std::size_t(f)], -1) << "face " << f << " in two cuts";
      owner[std::size_t(f)] = int(k);
      inside += g.pouch_of_face(f) == int(k);
      near += g.pouch_of_face(f, 2 * g.kH) == int(k);
    }
    for (std::size_t f = 0; f < g.s.t.size(); ++f) pouch_faces += g.pouch_of_face(int(f)) == int(k);
    EXPECT_EQ(near, cuts[k].faces.size());  // of the plane only the ring at the neck
    EXPECT_EQ(inside, pouch_faces);
    EXPECT_NEAR(cuts[k].area_mm2, g.pouches[k].area(), 0.1 * g.pouches[k].area());
    EXPECT_NEAR(cuts[k].neck_mm, 2 * M_PI * g.pouches[k].rn, 0.3 * 2 * M_PI * g.pouches[k].rn);
    EXPECT_FALSE(cuts[k].tissue);
  }
  ASSERT_EQ(runs[1].size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(runs[1][k].faces, cuts[k].faces);
    EXPECT_EQ(runs[1][k].area_mm2, cuts[k].area_mm2);
    EXPECT_EQ(runs[1][k].neck_mm, cuts[k].neck_mm);
  }
}

// A pouch with a pouch nested on its wall, on a plane (0..40 x 0..30 mm, 0.1 mm grid, z = 0). The
// outer pouch: inside the disk of radius kRb around cb = (15, 15) the grid rises as a cylinder of
// radius kRn (height kHc) topped by a sphere of radius kRs, so its shortest rim is the cylinder (2 pi
// kRn). Its map squeezes only the sphere's top (grid radius < kRc) to 1e-3; the rest of its wall
// keeps a few % of its area (not collapsed), the cylinder more. The inner pouch: the grid disk of
// radius kRa around ca = (17.5, 15) (on the outer sphere's equator) rises from the outer wall, along
// its normal, as a cylinder of radius kRna (height kHca) topped by a sphere of radius kRsa (its own
// neck 2 pi kRna, shorter than the outer one's), and the map squeezes its sphere (grid radius <
// kRaCore) to 1e-3 around its centre and opens linearly back to the outer map over its cylinder.
// The inner cluster is the larger (~200 mm2 against ~40), so it is taken first, and the outer
// pouch's neck encloses it: the outer pouch's search meets a branch taken before.
struct NestedPouches {
  static constexpr double kH = 0.1, kLength = 40, kWidth = 30, kSqueeze = 1e-3;
  static constexpr double kRb = 6, kRn = 3, kRs = 10, kHc = 10, kRc = 0.6, kF1 = 3;
  static constexpr double kRa = 1, kRna = 2, kRsa = 4, kHca = 4, kRaCore = 0.6;
  const flat_detail::V2 cb{15, 15}, ca{17.5, 15};
  flat_detail::Surface s;
  flat_detail::Embedding emb;
  flat_detail::Edges E;

  NestedPouches() {
    plane_grid(kH, kLength, kWidth, [this](const flat_detail::V2& q) { place(q); }, s, emb, E);
  }
  static double phi_max(double rn, double rs) { return M_PI - std::asin(rn / rs); }
  // Grid radius (from cb) of the outer sphere's foot.
  static double rho_sphere() { return kRb * kRs * phi_max(kRn, kRs) / (kRs * phi_max(kRn, kRs) + kHc); }
  // Wall area of a sphere of radius rs above a neck circle of radius rn.
  static double sphere_area(double rn, double rs) { return 2 * M_PI * rs * rs * (1 + std::sqrt(1 - rn * rn / (rs * rs))); }
  flat_detail::V2 grid_of(int v) const {
    const int nx = int(kLength / kH) + 1;
    return flat_detail::V2((v % nx) * kH, (v / nx) * kH);
  }
  // Whether all corners of face f lie within grid radius r of c.
  bool face_within(int f, const flat_detail::V2& c, double r) const {
    return std::all_of(s.t[f].begin(), s.t[f].end(), [&](int v) { return (grid_of(v) - c).norm() < r; });
  }

 private:
  // A pouch's profile at grid radius rho of its disk (radius R): (distance from its axis, height).
  static flat_detail::V2 profile(double rho, double R, double rn, double rs, double hc) {
    const double pm = phi_max(rn, rs), a = rho / R * (rs * pm + hc);  // arc length from the top
    const double zc = hc + rs * std::sqrt(1 - rn * rn / (rs * rs));
    if (a <= rs * pm) return {rs * std::sin(a / rs), zc + rs * std::cos(a / rs)};
    return {rn, hc - (a - rs * pm)};
  }
  // 3D point of grid point q on the plane with the outer pouch.
  static flat_detail::V3 outer_point(const flat_detail::V2& q) {
    const flat_detail::V2 c(15, 15), off = q - c;
    const double rho = off.norm();
    if (rho >= kRb) return {q.x(), q.y(), 0};
    const flat_detail::V2 gz = profile(rho, kRb, kRn, kRs, kHc);
    const flat_detail::V2 xy = rho > 0 ? flat_detail::V2(c + off / rho * gz.x()) : c;
    return {xy.x(), xy.y(), gz.y()};
  }
  // Flat radius of the outer pouch's grid radius rho: squeezed top, then sqrt (its area ratio
  // constant on the sphere), then linear on the cylinder, reaching the plane's own at kRb.
  static double flat_radius(double rho) {
    const double r1 = rho_sphere();
    if (rho < kRc) return kSqueeze * rho;
    if (rho < r1) return kSqueeze * kRc + kF1 * std::sqrt((rho - kRc) / (r1 - kRc));
    return kSqueeze * kRc + kF1 + (kRb - kF1 - kSqueeze * kRc) * (rho - r1) / (kRb - r1);
  }
  flat_detail::V2 outer_flat(const flat_detail::V2& q) const {
    const double rho = (q - cb).norm();
    return rho > 0 && rho < kRb ? flat_detail::V2(cb + (q - cb) / rho * flat_radius(rho)) : q;
  }
  // The inner pouch's 3D point: its profile in the outer wall's frame at ca (normal to the +z side).
  flat_detail::V3 inner_point(const flat_detail::V2& q) const {
    const double e = 1e-4;
    const flat_detail::V3 ex = outer_point(ca + flat_detail::V2(e, 0)) - outer_point(ca - flat_detail::V2(e, 0));
    const flat_detail::V3 ey = outer_point(ca + flat_detail::V2(0, e)) - outer_point(ca - flat_detail::V2(0, e));
    const flat_detail::V3 n = ex.cross(ey).normalized(), t1 = ex.normalized(), t2 = n.cross(t1);
    const flat_detail::V2 off = q - ca;
    const double rho = off.norm();
    const flat_detail::V2 gz = profile(rho, kRa, kRna, kRsa, kHca);
    const flat_detail::V2 dir = rho > 0 ? flat_detail::V2(off / rho) : flat_detail::V2(1, 0);
    return outer_point(ca) + gz.x() * (dir.x() * t1 + dir.y() * t2) + gz.y() * n;
  }
  void place(const flat_detail::V2& q) {
    const bool inner = (q - ca).norm() < kRa;
    s.p.push_back(inner ? inner_point(q) : outer_point(q));
    const flat_detail::V2 fa = outer_flat(ca);
    const double t = std::clamp(((q - ca).norm() - kRaCore) / (kRa - kRaCore), 0.0, 1.0);
    emb.pos.push_back(inner ? flat_detail::V2(fa + (kSqueeze + (1 - kSqueeze) * t) * (outer_flat(q) - fa)) : outer_flat(q));
  }
};

// The re-search path: the inner pouch's cluster is the larger and is taken first; the outer
// pouch's neck encloses it, so the outer search meets a taken branch and is done again. The result
// is one branch, the outer pouch cut at its neck holding the inner pouch (which is found again when
// the outer band is flattened), never two overlapping ones; the same for 1 and 2 threads.
TEST(FlattenBranches, PouchNestedInAPouchsNeckIsHeldByTheOuterBranchOnly) {
  const NestedPouches g;
  std::vector<std::vector<flat_detail::BranchCut>> runs;
  for (int threads : {2, 1}) {
    flat_detail::BranchSearch search;
    runs.push_back(branches_on_threads(g, threads, 20.0, search));
    EXPECT_GE(search.clusters, 2u);  // the two pouches' (and pieces of their rims, inside their branches)
    EXPECT_EQ(search.searched_again, 1u);
    EXPECT_EQ(search.absorbed, 1u);
  }
  const auto& cuts = runs[0];
  std::vector<int> owner(g.s.t.size(), -1);
  for (std::size_t k = 0; k < cuts.size(); ++k)
    for (int f : cuts[k].faces) {
      EXPECT_EQ(owner[std::size_t(f)], -1) << "face " << f << " in two cuts";
      owner[std::size_t(f)] = int(k);
    }
  ASSERT_EQ(cuts.size(), 1u);
  const auto& b = cuts[0];
  std::size_t sphere_faces = 0, sphere_cut = 0, inner_faces = 0, inner_cut = 0;
  for (std::size_t f = 0; f < g.s.t.size(); ++f) {
    const bool sphere = g.face_within(int(f), g.cb, g.rho_sphere()), inner = g.face_within(int(f), g.ca, g.kRa);
    sphere_faces += sphere, inner_faces += inner;
    sphere_cut += sphere && owner[f] == 0, inner_cut += inner && owner[f] == 0;
  }
  EXPECT_GT(inner_faces, 50u);
  EXPECT_EQ(inner_cut, inner_faces);    // the nested pouch is inside the outer branch
  EXPECT_EQ(sphere_cut, sphere_faces);  // and so is the outer pouch's whole sphere
  for (int f : b.faces) EXPECT_TRUE(g.face_within(f, g.cb, g.kRb)) << "face " << f << " beyond the outer pouch";
  // its wall: the outer sphere (less the patch the inner pouch replaces) and the inner pouch, some cylinder
  EXPECT_GT(b.area_mm2, g.sphere_area(g.kRn, g.kRs));
  EXPECT_LT(b.area_mm2, g.sphere_area(g.kRn, g.kRs) + g.sphere_area(g.kRna, g.kRsa) + 2 * M_PI * (g.kRna * g.kHca + g.kRn * g.kHc));
  EXPECT_NEAR(b.neck_mm, 2 * M_PI * g.kRn, 0.3 * 2 * M_PI * g.kRn);
  EXPECT_FALSE(b.tissue);
  ASSERT_EQ(runs[1].size(), 1u);
  EXPECT_EQ(runs[1][0].faces, b.faces);
  EXPECT_EQ(runs[1][0].neck_mm, b.neck_mm);
}

// A negative --branch-min-area is refused by `colonflat flatten` (usage error, one line, no output).
TEST(FlattenBranches, NegativeMinAreaIsRefused) {
  testing::TempDir tmp;
  write_mesh(synthetic::to_mesh(synthetic::open_cylinder(10, 50, 32, 40)), tmp / "in.vtp");
  const auto r = testing::run_stage_command(make_flatten_stage, {tmp.str("in.vtp"), "-o", tmp.str("flat.vtp"), "--branch-min-area", "-5"});
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err.rfind("colonflat flatten: error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("branch-min-area"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(tmp / "flat.vtp"));
}

// A tube (32 x 40 quads) and cuts as find_branches gives them: one in the middle is made; one that
// takes a notch out of an end ring, and one that leaves only a row of faces the clean-up removes
// before the ring, are dropped, so every vertex of both ends stays a corner of a kept face (the
// end loops are the harmonic solve's boundary: a lost vertex wrote outside the band's arrays).
TEST(FlattenBranches, CutsThatWouldTakeAnEndVertexAreDroppedAndTheEndsStayWhole) {
  const TriangleList tube = synthetic::open_cylinder(10, 80, 32, 40);
  flat_detail::Surface s;
  for (const auto& p : tube.points) s.p.emplace_back(p[0], p[1], p[2]);
  s.t.assign(tube.triangles.begin(), tube.triangles.end());
  const flat_detail::Edges E = flat_detail::build_edges(s.t);
  const std::vector<std::vector<int>> ends = flat_detail::boundary_loops(s, E);
  ASSERT_EQ(ends.size(), 2u);
  const auto quads = [](int j0, int j1, int i0, int i1) {  // both triangles of quads [j0, j1) x [i0, i1)
    flat_detail::BranchCut c;
    for (int j = j0; j < j1; ++j)
      for (int i = i0; i < i1; ++i) c.faces.push_back(2 * (j * 32 + i)), c.faces.push_back(2 * (j * 32 + i) + 1);
    return c;
  };
  const flat_detail::BranchCut middle = quads(18, 22, 5, 9), notch = quads(0, 3, 20, 24), near_end = quads(1, 4, 12, 15);
  std::vector<flat_detail::BranchCut> cuts = {notch, middle, near_end};
  const std::vector<char> keep = flat_detail::band_faces_after_cuts(s, E, ends, cuts);
  ASSERT_EQ(cuts.size(), 1u);
  EXPECT_EQ(cuts[0].faces, middle.faces);
  std::vector<char> want(s.t.size(), 1), corner(s.p.size(), 0);
  for (int f : middle.faces) want[std::size_t(f)] = 0;
  EXPECT_EQ(keep, want);
  for (std::size_t f = 0; f < s.t.size(); ++f)
    if (keep[f])
      for (int v : s.t[f]) corner[std::size_t(v)] = 1;
  for (const auto& end : ends)
    for (int v : end) EXPECT_TRUE(corner[std::size_t(v)]) << "end vertex " << v;
  // Only cuts at the ends: none is made, and the band keeps every face.
  std::vector<flat_detail::BranchCut> end_cuts = {notch, near_end};
  EXPECT_EQ(flat_detail::band_faces_after_cuts(s, E, ends, end_cuts), std::vector<char>(s.t.size(), 1));
  EXPECT_TRUE(end_cuts.empty());
}

}  // namespace
}  // namespace cf
