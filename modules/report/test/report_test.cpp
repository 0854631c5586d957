// The review report: colon-image layout and lookup, CT planes, Slicer markups, the report command
// and its errors (on a small synthetic run folder built in the test).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>
#include <set>
#include <sstream>

#include "colonflat/flatten/flat_artifact.h"
#include "colonflat/render/artifacts.h"
#include "colonflat/core/synthetic.h"
#include "colonflat/report/ct_views.h"
#include "colonflat/report/endoluminal.h"
#include "colonflat/report/image_layout.h"
#include "colonflat/report/report_tool.h"
#include "colonflat/report/slicer_markups.h"
#include "colonflat/core/stage.h"
#include "colonflat/testing/temp_dir.h"
#include "synthetic_run.h"

#include <vtkImageData.h>

namespace fs = std::filesystem;

namespace cf {
namespace {

struct ToolResult {
  int code;
  std::string out, err;
};
ToolResult run_report_tool(const std::vector<std::string>& args) {
  std::ostringstream out, err;
  const int code = make_report_tool()->run(args, out, err);
  return {code, out.str(), err.str()};
}

// The layout rebuilt from flat.vtp matches render's image size and puts every candidate where
// render drew it, on a two-segment map with candidates in both bands; a wrong size is reported.
TEST(ReportLayout, MatchesRenderedImageAndCandidatePixels) {
  testing::TempDir tmp;
  const auto run = testing::make_synthetic_run(tmp / "run");
  const FlatMap flat = read_flat(tmp / "run" / "flat.vtp");
  ASSERT_EQ(flat.segments.size(), 2u);
  const ImagePtr png = read_png(tmp / "run" / "colon.png");
  int dims[3];
  png->GetDimensions(dims);
  ColonImageLayout layout(flat, run.candidates["image"]["pixel_size_mm"].get<double>());
  layout.set_rolls_from_candidates(run.candidates["candidates"]);
  EXPECT_EQ(layout.check(dims[0], dims[1], run.candidates["candidates"]), "");
  std::set<int> segments_with_candidates;
  for (const auto& c : run.candidates["candidates"]) segments_with_candidates.insert(c["segment"].get<int>());
  EXPECT_EQ(segments_with_candidates.size(), 2u) << "the check must cover both bands";
  // a wrong image size is reported
  EXPECT_NE(layout.check(dims[0] + 5, dims[1], run.candidates["candidates"]), "");
}

// Every lookup cell names a flat vertex inside that cell: sampled vertices find a cell whose
// vertex lies within one cell diagonal (in flat mm) of them.
TEST(ReportLayout, LookupCellsPointAtNearbyWall) {
  testing::TempDir tmp;
  const auto run = testing::make_synthetic_run(tmp / "run");
  const FlatMap flat = read_flat(tmp / "run" / "flat.vtp");
  const double px = run.candidates["image"]["pixel_size_mm"].get<double>();
  ColonImageLayout layout(flat, px);
  layout.set_rolls_from_candidates(run.candidates["candidates"]);
  const LookupGrid grid = build_lookup_grid(flat, layout, 6);
  std::mt19937 rng(3);
  int checked = 0;
  for (int k = 0; k < 400; ++k) {
    const int v = int(rng() % flat.uv.size());
    const auto p = layout.to_pixel(flat.segment[v], flat.uv[v][0], flat.uv[v][1]);
    const int cell = int(p[1] / 6) * grid.cols + int(p[0] / 6);
    const int w = grid.vertex.at(cell);
    ASSERT_GE(w, 0);
    EXPECT_EQ(flat.segment[w], flat.segment[v]);
    const auto q = layout.to_pixel(flat.segment[w], flat.uv[w][0], flat.uv[w][1]);
    EXPECT_LE(std::hypot(q[0] - p[0], q[1] - p[1]), 6 * std::sqrt(2.0) + 1e-9);
    ++checked;
  }
  EXPECT_EQ(checked, 400);
}

// A plane around a point shows the point at its centre, and follows radiological convention:
// patient left (+L) right of centre in axial and coronal, superior (+S) above centre.
TEST(ReportCt, PlanesCentredOnPointInRadiologicalConvention) {
  const std::array<double, 3> c{10, -20, 30};
  const auto ct = testing::ball_ct({-20, -50, 0}, {40, 10, 60}, c);
  const int n = 61;  // 1 mm pixels, centre pixel 30
  for (Plane plane : {Plane::axial, Plane::coronal, Plane::sagittal}) {
    const PlaneImage im = sample_plane_around(ct.GetPointer(), plane, c, 61.0, n);
    auto hu = [&](int col, int row) { return im.hu[std::size_t(row) * n + col]; };
    EXPECT_GT(hu(30, 30), 500) << plane_name(plane);
    EXPECT_LT(hu(2, 2), -900) << plane_name(plane);
    if (plane != Plane::sagittal) {
      EXPECT_GT(hu(42, 30), 500) << "+L ball right of centre in " << plane_name(plane);
    }
    if (plane != Plane::axial) {
      EXPECT_GT(hu(30, 18), 500) << "+S ball above centre in " << plane_name(plane);
    }
  }
}

// polyps.mrk.json follows the Slicer markups schema (v1.0.3) for every field it uses: one point
// list, LPS, mm, one defined control point per candidate with string label/description.
TEST(ReportMarkups, FieldsFollowSlicerSchema) {
  const nlohmann::json doc = slicer_point_list("c", {{"P1", "8 mm", {1, 2, 3}}, {"P2", "5 mm", {4, 5, 6}}}, {1, 0.8, 0});
  ASSERT_TRUE(doc["@schema"].is_string());
  EXPECT_NE(doc["@schema"].get<std::string>().find("markups-schema-v1.0.3.json"), std::string::npos);
  ASSERT_TRUE(doc["markups"].is_array());
  ASSERT_EQ(doc["markups"].size(), 1u);
  const auto& m = doc["markups"][0];
  const std::set<std::string> types = {"Fiducial", "Line", "Angle", "Curve", "ClosedCurve", "Plane", "ROI"};
  EXPECT_TRUE(types.count(m["type"].get<std::string>()));
  EXPECT_EQ(m["type"], "Fiducial");
  EXPECT_EQ(m["coordinateSystem"], "LPS");  // enum LPS | RAS
  EXPECT_EQ(m["coordinateUnits"], "mm");    // enum mm | um
  EXPECT_TRUE(m["locked"].is_boolean());
  EXPECT_TRUE(m["labelFormat"].is_string());
  ASSERT_EQ(m["controlPoints"].size(), 2u);
  for (const auto& cp : m["controlPoints"]) {
    for (const char* s : {"id", "label", "description", "associatedNodeID"}) EXPECT_TRUE(cp[s].is_string()) << s;
    for (const char* b : {"selected", "locked", "visibility"}) EXPECT_TRUE(cp[b].is_boolean()) << b;
    ASSERT_EQ(cp["position"].size(), 3u);
    for (const auto& v : cp["position"]) EXPECT_TRUE(v.is_number());
    ASSERT_EQ(cp["orientation"].size(), 9u);
    const std::set<std::string> status = {"undefined", "preview", "defined"};
    EXPECT_TRUE(status.count(cp["positionStatus"].get<std::string>()));
  }
  EXPECT_EQ(m["controlPoints"][1]["position"][2].get<double>(), 6.0);
  const auto& d = m["display"];
  for (const char* c : {"color", "selectedColor"}) {
    ASSERT_EQ(d[c].size(), 3u);
    for (const auto& v : d[c]) EXPECT_TRUE(v.get<double>() >= 0 && v.get<double>() <= 1);
  }
  EXPECT_EQ(d["glyphType"], "Sphere3D");
  EXPECT_TRUE(d["opacity"].get<double>() >= 0 && d["opacity"].get<double>() <= 1);
}

// `colonflat report RUN` writes a page with no network reference, the Slicer files (one point
// per candidate / known polyp, at their LPS) and the images; the top candidate's axial CT view
// is centred on it (bright ball in the middle, air at the corner).
TEST(ReportTool, WritesPageMarkupsAndImages) {
  testing::TempDir tmp;
  const auto run = testing::make_synthetic_run(tmp / "run");
  const auto r = run_report_tool({(tmp / "run").string(), "--quiet"});
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream in(tmp / "run" / "report.html");
  const std::string html((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const char* net : {"src=\"http", "href=\"http", "<link", "url(http", "@import", "fetch("})
    EXPECT_EQ(html.find(net), std::string::npos) << net;
  EXPECT_NE(html.find("window.REPORT = "), std::string::npos);
  const auto mrk = read_json_file(tmp / "run" / "polyps.mrk.json");
  const auto& cps = mrk["markups"][0]["controlPoints"];
  ASSERT_EQ(cps.size(), run.candidates["candidates"].size());
  EXPECT_EQ(read_json_file(tmp / "run" / "known_polyps.mrk.json")["markups"][0]["controlPoints"].size(),
            std::size_t(run.known_polyps));
  // the first point is the top-scoring candidate, at its LPS position
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(cps[0]["position"][k].get<double>(), run.top_candidate[k], 0.051);
  const std::string key = cps[0]["label"].get<std::string>();
  const ImagePtr axial = read_png(tmp / "run" / "report_files" / (key + "_axial_lung.png"));
  int dims[3];
  axial->GetDimensions(dims);
  auto grey = [&](int c, int r) { return *static_cast<unsigned char*>(axial->GetScalarPointer(c, dims[1] - 1 - r, 0)); };
  EXPECT_GT(grey(dims[0] / 2, dims[1] / 2), 200);
  EXPECT_EQ(grey(1, 1), 0);
  for (const char* f : {"_coronal_soft.png", "_sagittal_lung.png", "_flat.png"})
    EXPECT_TRUE(fs::exists(tmp / "run" / "report_files" / (key + f))) << f;
  EXPECT_TRUE(fs::exists(tmp / "run" / "report_files" / "axial_0.png"));
}

// Without candidates.json the report reads the older polyps.json (contract 2).
TEST(ReportTool, FallsBackToPolypsJson) {
  testing::TempDir tmp;
  const auto run = testing::make_synthetic_run(tmp / "run");
  fs::rename(tmp / "run" / "candidates.json", tmp / "run" / "polyps.json");
  const auto r = run_report_tool({(tmp / "run").string(), "--quiet", "--no-endoluminal"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(read_json_file(tmp / "run" / "polyps.mrk.json")["markups"][0]["controlPoints"].size(),
            run.candidates["candidates"].size());
}

// Bad input: one error line naming the file, non-zero exit, nothing written.
TEST(ReportTool, RejectsBadInputWithoutPartialOutput) {
  testing::TempDir tmp;
  auto r = run_report_tool({(tmp / "missing").string()});
  EXPECT_EQ(r.code, 3);
  EXPECT_EQ(r.err, "colonflat report: error: " + (tmp / "missing").string() + ": no such run folder\n");
  fs::create_directories(tmp / "empty");
  r = run_report_tool({(tmp / "empty").string()});
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("no run_report.json"), std::string::npos);
  testing::make_synthetic_run(tmp / "run");
  std::ofstream(tmp / "run" / "candidates.json") << "{\"candidates\": [{\"id\": 1}]}";
  r = run_report_tool({(tmp / "run").string(), "--quiet"});
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("candidates.json: candidate 1 has no position_lps_mm"), std::string::npos) << r.err;
  for (const auto& e : fs::directory_iterator(tmp / "run")) {
    const std::string name = e.path().filename().string();
    EXPECT_TRUE(name.rfind("report", 0) != 0 && name.rfind(".report", 0) != 0) << name;
  }
  EXPECT_FALSE(fs::exists(tmp / "run" / "polyps.mrk.json"));
}

// Parameters out of range are rejected before anything is read.
TEST(ReportTool, RejectsInvalidParameters) {
  testing::TempDir tmp;
  for (const auto& bad : std::vector<std::vector<std::string>>{{"--tile-pixels", "5"}, {"--stack-step", "0"},
                                                               {"--min-fov", "90", "--max-fov", "40"}}) {
    std::vector<std::string> args = {(tmp / "x").string()};
    args.insert(args.end(), bad.begin(), bad.end());
    const auto r = run_report_tool(args);
    EXPECT_EQ(r.code, 2) << bad[0] << ": " << r.err;
    EXPECT_NE(r.err.find("colonflat report: error:"), std::string::npos);
  }
}

}  // namespace
}  // namespace cf

namespace cf {
namespace {

// Inside a straight tube the endoluminal view of a wall point is the lit wall: most pixels are
// tissue-coloured (red > blue), none of the view is empty background at the centre.
TEST(ReportEndoluminal, ViewFromInsideTubeShowsLitWall) {
  const TriangleList tube = synthetic::open_cylinder(15, 200, 96, 200);
  std::vector<std::array<double, 3>> normals;
  for (const auto& p : tube.points) {
    const double r = std::hypot(p[0], p[1]);
    normals.push_back({p[0] / r, p[1] / r, 0});  // out of the lumen
  }
  EndoluminalOptions o;
  o.size = 64;
  EndoluminalRenderer endo(tube, normals, o);
  double d = 0;
  const ImagePtr img = endo.render({15, 0, 100}, {1, 0, 0}, &d);
  EXPECT_NEAR(d, 0.6 * 29, 1.0);  // 60 % of the 30 mm free distance (minus the 1 mm start)
  int lit = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const auto* p = static_cast<unsigned char*>(img->GetScalarPointer(x, y, 0));
      if (p[0] > 60 && p[0] > p[2]) ++lit;
    }
  EXPECT_GT(lit, 64 * 64 * 9 / 10);
  const auto* centre = static_cast<unsigned char*>(img->GetScalarPointer(32, 32, 0));
  EXPECT_GT(centre[0], 100);
}

}  // namespace
}  // namespace cf
