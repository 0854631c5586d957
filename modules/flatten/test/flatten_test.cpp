// Conformal flattening: analytic cylinder, closed synthetic colons, several segments, genus > 0
// refusal, the flat .vtp round trip and the `colonflat flatten` command.
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

namespace cf {
namespace {

synthetic::ColonOptions small_colon() { return synthetic::colon_options(300, 18, 1.2, {{80, 0.5, 8}, {200, 2.5, 10}}); }

// An open cylinder maps to a rectangle: length = height, period = circumference, ratio ~1, no flips.
TEST(FlattenCylinder, MapsToRectangleWithAspectLengthOverCircumference) {
  const double r = 10, h = 100;
  FlatMap f = flatten_colon(synthetic::open_cylinder(r, h, 96, 150));
  ASSERT_EQ(f.segments.size(), 1u);
  const FlatSegment& s = f.segments[0];
  EXPECT_EQ(s.input_kind, "tube");
  EXPECT_NEAR(s.length, h, 0.01 * h);
  EXPECT_NEAR(s.period, 2 * M_PI * r, 0.01 * 2 * M_PI * r);
  EXPECT_NEAR(s.length / s.period, h / (2 * M_PI * r), 0.01 * h / (2 * M_PI * r));
  EXPECT_EQ(f.stats.flipped, 0u);
  EXPECT_LT(f.stats.qc_mean, 1.01);
  EXPECT_LT(f.stats.qc_max, 1.1);
  EXPECT_NEAR(f.stats.area_median, 1.0, 0.02);
  // every 2D point lies in the rectangle, up to one triangle across the cut
  for (const auto& q : f.uv) {
    EXPECT_GE(q[0], -1e-9);
    EXPECT_LE(q[0], s.length + 1e-9);
    EXPECT_GT(q[1], -2.0);
    EXPECT_LT(q[1], s.period + 2.0);
  }
}

// A closed, bent colon with folds and polyps: both ends opened, 0 flipped, mean ratio <= 1.15
// (area-balanced default; the conformal map <= 1.05).
TEST(FlattenColon, ClosedBentColonIsFlatWithoutFlips) {
  auto c = synthetic::colon(small_colon());
  FlatMap f = flatten_colon(c.mesh);
  ASSERT_EQ(f.segments.size(), 1u);
  const FlatSegment& s = f.segments[0];
  EXPECT_EQ(s.input_kind, "closed");
  EXPECT_GT(s.removed_faces, 0u);
  EXPECT_EQ(f.stats.flipped, 0u);
  EXPECT_LE(f.stats.qc_mean, 1.15);
  FlattenOptions conformal;
  conformal.map = "conformal";
  EXPECT_LE(flatten_colon(c.mesh, conformal).stats.qc_mean, 1.05);
  // the ends are the two caps: about length + 2 radii apart along the bent centreline
  const double d = std::hypot(s.end_a[0] - s.end_b[0], s.end_a[1] - s.end_b[1], s.end_a[2] - s.end_b[2]);
  EXPECT_GT(d, 200.0);
  EXPECT_NEAR(s.period, c.circumference, 0.15 * c.circumference);
  // the 3D <-> 2D correspondence: every flat vertex carries its input position
  for (std::size_t i = 0; i < f.uv.size(); i += 97) {
    const auto& p = c.mesh.points[f.source_vertex[i]];
    EXPECT_EQ(p, f.position[i]);
  }
}

// Two disjoint segments give two rectangles that do not overlap in the layout.
TEST(FlattenColon, SeveralSegmentsGiveOneRectangleEach) {
  auto a = synthetic::colon(small_colon());
  auto o = small_colon();
  o.length = 200;
  o.polyps.clear();
  auto b = synthetic::colon(o);
  FlatMap f = flatten_colon(synthetic::disjoint_union(a.mesh, synthetic::translated(b.mesh, 0, 200, 0)));
  ASSERT_EQ(f.segments.size(), 2u);
  EXPECT_EQ(f.stats.flipped, 0u);
  const auto &s0 = f.segments[0], &s1 = f.segments[1];
  EXPECT_GE(s1.y0, s0.y0 + s0.period);
  EXPECT_EQ(s0.order, 0);
  EXPECT_EQ(s1.order, 1);
  for (std::size_t i = 0; i < f.uv.size(); ++i) {
    const auto& s = f.segments[f.segment[i]];
    EXPECT_GT(f.uv[i][1], s.y0 - 3.0);
    EXPECT_LT(f.uv[i][1], s.y0 + s.period + 3.0);
  }
}

// A surface with a handle is refused with a message saying to run denoise first.
TEST(FlattenColon, GenusAboveZeroIsRefused) {
  try {
    flatten_colon(synthetic::torus(30, 10, 48, 24));
    FAIL() << "no error";
  } catch (const PreconditionError& e) {
    EXPECT_NE(std::string(e.what()).find("genus 1"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("run denoise first"), std::string::npos) << e.what();
    EXPECT_EQ(e.exit_code(), kExitBadInput);
  }
}

// The flat map survives a .vtp write/read: points, 3D positions, segments and distortion.
TEST(FlattenFlatFile, RoundTrip) {
  testing::TempDir tmp;
  FlatMap f = flatten_colon(synthetic::open_cylinder(10, 60, 48, 60));
  write_flat(f, tmp / "flat.vtp");
  FlatMap g = read_flat(tmp / "flat.vtp");
  ASSERT_EQ(g.uv.size(), f.uv.size());
  ASSERT_EQ(g.triangles.size(), f.triangles.size());
  ASSERT_EQ(g.segments.size(), 1u);
  EXPECT_DOUBLE_EQ(g.segments[0].period, f.segments[0].period);
  EXPECT_EQ(g.position[5], f.position[5]);
  EXPECT_EQ(g.uv[7], f.uv[7]);
  EXPECT_EQ(g.stats.flipped, 0u);
  EXPECT_NEAR(g.stats.qc_mean, f.stats.qc_mean, 1e-9);
  std::ofstream(tmp / "bad.vtp") << "<VTKFile>";
  EXPECT_THROW(read_flat(tmp / "bad.vtp"), InputError);
}

testing::CommandResult flatten_cli(const std::vector<std::string>& args) {
  return testing::run_stage_command(make_flatten_stage, args);
}

// `colonflat flatten` writes the flat map and a report with 0 flipped triangles.
TEST(FlattenCli, WritesFlatMapAndReport) {
  testing::TempDir tmp;
  write_mesh(synthetic::to_mesh(synthetic::colon(small_colon()).mesh), tmp / "denoised.vtp");
  auto r = flatten_cli({tmp.str("denoised.vtp"), "-o", tmp.str("flat.vtp"), "--report", tmp.str("r.json"), "-q"});
  ASSERT_EQ(r.code, 0) << r.err;
  FlatMap f = read_flat(tmp / "flat.vtp");
  EXPECT_EQ(f.segments.size(), 1u);
  std::ifstream in(tmp / "r.json");
  auto j = nlohmann::json::parse(in);
  EXPECT_EQ(j["result"]["distortion"]["flipped_triangles"], 0);
  EXPECT_LE(j["result"]["distortion"]["quasi_conformal_mean"].get<double>(), 1.15);
  EXPECT_GE(j["result"]["coverage"]["fraction_shown"].get<double>(), 0.995);
}

// Genus > 0 on the command line: exit code 3 and one error line naming denoise.
TEST(FlattenCli, GenusAboveZeroExitsWithBadInput) {
  testing::TempDir tmp;
  write_mesh(synthetic::to_mesh(synthetic::torus_chain(2, 20, 6, 32, 16, 60)), tmp / "handles.vtp");
  auto r = flatten_cli({tmp.str("handles.vtp"), "-o", tmp.str("flat.vtp")});
  EXPECT_EQ(r.code, 3);
  EXPECT_EQ(r.err.rfind("colonflat flatten: error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("genus 2"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("run denoise first"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1);
  EXPECT_FALSE(std::filesystem::exists(tmp / "flat.vtp"));
}

}  // namespace
}  // namespace cf
