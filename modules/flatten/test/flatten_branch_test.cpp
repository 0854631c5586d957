// Side branches (branches.cpp): a pouch the conformal map collapses is cut at its neck and shown
// as a band of its own; nothing of the kind on a plain tube; the fields survive the flat file.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "colonflat/core/error.h"
#include "colonflat/core/mesh_io.h"
#include "colonflat/core/synthetic.h"
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
// band at the neck (LPS ~ (120, 12..32, 0), neck length ~ 2 pi 3 mm), and the whole wall shown.
TEST(FlattenBranches, PouchBehindNarrowNeckIsABandOfItsOwn) {
  const TriangleList mesh = test_shapes::pouch_behind_neck(3.0);
  const FlatMap f = flatten_colon(mesh);
  ASSERT_EQ(f.segments.size(), 2u);
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

}  // namespace
}  // namespace cf
