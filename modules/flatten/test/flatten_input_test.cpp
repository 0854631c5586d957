// What flatten does with inputs that are not a ready outward colon (issue 29): an inward colon is
// reversed by the stage (same map as the outward one) and refused by the library with the cause;
// every rejected component is named with its size and reason (too small, a cavity's wall).
#include <gtest/gtest.h>

#include <fstream>

#include "colonflat/core/error.h"
#include "colonflat/core/mesh_io.h"
#include "colonflat/flatten/flat_artifact.h"
#include "colonflat/flatten/flatten.h"
#include "colonflat/flatten/flatten_stage.h"
#include "colonflat/testdata/synthetic.h"
#include "colonflat/testdata/synthetic_colon.h"
#include "colonflat/testing/stage_command.h"
#include "colonflat/testing/temp_dir.h"

namespace cf {
namespace {

TriangleList reversed(TriangleList t) {
  for (auto& tr : t.triangles) std::swap(tr[1], tr[2]);
  return t;
}

// A straight closed colon along z (100 mm, radius 10, 2 mm triangles), outward.
TriangleList straight_colon() {
  synthetic::ColonOptions o = synthetic::colon_options(100, 10, 2.0, {});
  o.bent = false;
  return synthetic::colon(o).mesh;
}

std::array<double, 3> centroid(const TriangleList& t) {
  std::array<double, 3> c{0, 0, 0};
  for (const auto& p : t.points)
    for (int k = 0; k < 3; ++k) c[k] += p[k] / double(t.points.size());
  return c;
}

std::string error_of(const TriangleList& t) {
  try {
    flatten_colon(t);
  } catch (const PreconditionError& e) {
    return e.what();
  }
  return "(no error)";
}

// The library refuses an inward colon naming the component, its size and the cause.
TEST(FlattenInput, InwardColonIsRefusedByTheLibraryWithTheCause) {
  const TriangleList inward = reversed(straight_colon());
  const std::string e = error_of(inward);
  EXPECT_NE(e.find("component 0 (" + std::to_string(inward.triangles.size()) + " faces, "), std::string::npos) << e;
  EXPECT_NE(e.find("normals point into the lumen"), std::string::npos) << e;
  EXPECT_EQ(e.find("large enough"), std::string::npos) << e;
}

// `colonflat flatten` on the inward colon: the same map as on the outward one (segments, length,
// coverage, triangles), the report and a progress line say the component was reversed.
TEST(FlattenInput, InwardColonThroughTheStageEqualsOutward) {
  testing::TempDir tmp;
  const TriangleList outward = straight_colon();
  write_mesh(synthetic::to_mesh(outward), tmp / "out.vtp");
  write_mesh(synthetic::to_mesh(reversed(outward)), tmp / "in.vtp");
  for (const char* n : {"out", "in"}) {
    const auto r = testing::run_stage_command(make_flatten_stage, {tmp.str(std::string(n) + ".vtp"), "-o",
                                                                   tmp.str(std::string(n) + "_flat.vtp"), "--report",
                                                                   tmp.str(std::string(n) + ".json")});
    ASSERT_EQ(r.code, 0) << r.err;
    if (std::string(n) == "in")
      EXPECT_NE(r.err.find("flatten: denoised: component 0 ("), std::string::npos) << r.err;
  }
  const FlatMap a = read_flat(tmp / "out_flat.vtp"), b = read_flat(tmp / "in_flat.vtp");
  ASSERT_EQ(a.segments.size(), 1u);
  ASSERT_EQ(b.segments.size(), 1u);
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_DOUBLE_EQ(a.segments[0].length, b.segments[0].length);
  EXPECT_DOUBLE_EQ(a.coverage.fraction, b.coverage.fraction);
  std::ifstream in(tmp / "in.json"), out(tmp / "out.json");
  const auto ji = nlohmann::json::parse(in), jo = nlohmann::json::parse(out);
  EXPECT_EQ(ji["result"]["orientation"]["reversed_components"], 1);
  EXPECT_EQ(jo["result"]["orientation"]["reversed_components"], 0);
  EXPECT_NE(ji["result"]["orientation"]["notes"][0].get<std::string>().find("normals pointed into the lumen; reversed"),
            std::string::npos);
}

// Only tiny pieces: the error names each with its size and "too small", not a missing colon.
TEST(FlattenInput, TinyComponentsAreNamedTooSmall) {
  const TriangleList tiny = synthetic::disjoint_union(synthetic::sphere(1, 3, 2), synthetic::translated(synthetic::sphere(1, 3, 2), 5, 0, 0));
  const std::string e = error_of(tiny);
  EXPECT_EQ(e.rfind("no component to flatten: component 0 (6 faces, ", 0), 0u) << e;
  EXPECT_NE(e.find("too small: fewer than 8 faces"), std::string::npos) << e;
  EXPECT_NE(e.find("component 1 (6 faces"), std::string::npos) << e;
}

// A blob floating in the lumen (a closed wall facing into itself, inside the colon) is skipped
// with its reason; the colon is flattened.
TEST(FlattenInput, CavityWallIsSkippedWithItsReason) {
  const TriangleList colon = straight_colon();
  const auto c = centroid(colon);
  const TriangleList blob = synthetic::translated(reversed(synthetic::sphere(3, 16, 8)), c[0], c[1], c[2]);
  const FlatMap f = flatten_colon(synthetic::disjoint_union(colon, blob));
  EXPECT_EQ(f.segments.size(), 1u);
  ASSERT_EQ(f.skipped.size(), 1u);
  EXPECT_NE(f.skipped[0].find("component 1 (224 faces, "), std::string::npos) << f.skipped[0];
  EXPECT_NE(f.skipped[0].find("the wall of a cavity"), std::string::npos) << f.skipped[0];
}

// A component open in 3 places is refused with its size and the count of openings.
TEST(FlattenInput, ThreeOpeningsAreNamed) {
  TriangleList t = synthetic::sphere(10, 24, 12);
  std::vector<std::array<int, 3>> kept;
  for (std::size_t f = 0; f < t.triangles.size(); ++f)
    if (f != 0 && f != 200 && f != 400) kept.push_back(t.triangles[f]);  // three separate holes
  t.triangles = kept;
  const std::string e = error_of(t);
  EXPECT_NE(e.find("is open in 3 places"), std::string::npos) << e;
  EXPECT_NE(e.find("component 0 (" + std::to_string(kept.size()) + " faces"), std::string::npos) << e;
}

}  // namespace
}  // namespace cf
