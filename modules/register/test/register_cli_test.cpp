// `colonflat register` as a command: outputs, and one-line errors for invalid inputs.
#include <gtest/gtest.h>

#include <vtkDataArray.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkImageData.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkXMLPolyDataReader.h>

#include <algorithm>
#include <fstream>
#include <sstream>

#include "colonflat/core/stage.h"
#include "colonflat/register/register.h"
#include "colonflat/register/register_tool.h"
#include "colonflat/register/scan.h"
#include "colonflat/report/report.h"
#include "colonflat/testdata/synthetic_pair.h"
#include "colonflat/testing/temp_dir.h"

namespace cf {
namespace {
namespace fs = std::filesystem;

struct Result {
  int code;
  std::string out, err;
};

Result run_register(const std::vector<std::string>& args) {
  std::ostringstream out, err;
  const int code = make_register_tool()->run(args, out, err);
  return {code, out.str(), err.str()};
}

// Writes a synthetic pair as two run folders DIR/supine and DIR/prone.
void write_pair(const fs::path& dir) {
  const SyntheticPair pair = make_synthetic_pair({});
  write_run_dir(pair.supine, dir / "supine");
  write_run_dir(pair.prone, dir / "prone");
}

void expect_one_error_line(const Result& r, int code, const std::string& mention) {
  EXPECT_EQ(r.code, code) << r.err;
  EXPECT_EQ(r.err.rfind("colonflat register: error: ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(mention), std::string::npos) << r.err;
}

// The command writes the four files; the correspondence .vtp has one prone vertex per supine
// point, the JSON lists the six polyp pairs, the PNG has two bands.
TEST(RegisterCli, WritesCorrespondenceJsonAndImage) {
  testing::TempDir tmp;
  write_pair(tmp.path());
  const Result r = run_register({tmp.str("supine"), tmp.str("prone"), "-o", tmp.str("out"), "-q"});
  ASSERT_EQ(r.code, 0) << r.err;
  vtkNew<vtkXMLPolyDataReader> reader;
  reader->SetFileName(tmp.str("out/supine_to_prone.vtp").c_str());
  reader->Update();
  vtkDataArray* v = reader->GetOutput()->GetPointData()->GetArray("prone_vertex");
  ASSERT_NE(v, nullptr);
  EXPECT_EQ(v->GetNumberOfTuples(), reader->GetOutput()->GetNumberOfPoints());
  EXPECT_GE(v->GetRange()[0], 0.0);
  ASSERT_NE(reader->GetOutput()->GetPointData()->GetArray("prone_position_lps_mm"), nullptr);
  std::ifstream in(tmp / "out/registration.json");
  const auto j = nlohmann::json::parse(in);
  EXPECT_EQ(j["candidates"]["pairs"].size(), 6u);
  EXPECT_EQ(j["units"], "mm");
  EXPECT_GT(j["length_alignment"]["knots"].size(), 40u);
  EXPECT_TRUE(fs::exists(tmp / "out/prone_to_supine.vtp"));
  vtkNew<vtkPNGReader> png;
  png->SetFileName(tmp.str("out/supine_prone.png").c_str());
  png->Update();
  EXPECT_GT(png->GetOutput()->GetDimensions()[0], 500);
  EXPECT_GT(png->GetOutput()->GetDimensions()[1], 2 * 60);
}

// Phantom-style runs without candidates.json: polyps.json is read instead.
TEST(RegisterCli, FallsBackToPolypsJson) {
  testing::TempDir tmp;
  write_pair(tmp.path());
  for (const char* side : {"supine", "prone"})
    fs::rename(tmp / side / "candidates.json", tmp / side / "polyps.json");
  ASSERT_EQ(run_register({tmp.str("supine"), tmp.str("prone"), "-o", tmp.str("out"), "-q"}).code, 0);
  std::ifstream in(tmp / "out/registration.json");
  const auto j = nlohmann::json::parse(in);
  EXPECT_EQ(j["supine"]["candidates_file"], "polyps.json");
  EXPECT_EQ(j["candidates"]["pairs"].size(), 6u);
}

// A missing run folder: exit 3, one error line naming it, no output folder.
TEST(RegisterCli, MissingRunDirIsBadInput) {
  testing::TempDir tmp;
  write_pair(tmp.path());
  const Result r = run_register({tmp.str("nothere"), tmp.str("prone"), "-o", tmp.str("out")});
  expect_one_error_line(r, 3, "nothere");
  EXPECT_FALSE(fs::exists(tmp / "out"));
}

// A flat.vtp that is not VTK XML: exit 3 naming the file.
TEST(RegisterCli, CorruptFlatMapIsBadInput) {
  testing::TempDir tmp;
  write_pair(tmp.path());
  std::ofstream(tmp / "prone/flat.vtp") << "not a vtp";
  expect_one_error_line(run_register({tmp.str("supine"), tmp.str("prone"), "-o", tmp.str("out")}), 3, "flat.vtp");
  EXPECT_FALSE(fs::exists(tmp / "out"));
}

// A candidates.json that is not JSON, or an entry without a position: exit 3 naming the file.
TEST(RegisterCli, MalformedCandidatesAreBadInput) {
  testing::TempDir tmp;
  write_pair(tmp.path());
  std::ofstream(tmp / "supine/candidates.json") << "{ broken";
  expect_one_error_line(run_register({tmp.str("supine"), tmp.str("prone"), "-o", tmp.str("out")}), 3,
                        "candidates.json");
  std::ofstream(tmp / "supine/candidates.json") << R"({"candidates":[{"id":1}]})";
  expect_one_error_line(run_register({tmp.str("supine"), tmp.str("prone"), "-o", tmp.str("out")}), 3,
                        "position_lps_mm");
  EXPECT_FALSE(fs::exists(tmp / "out"));
}

// A flat map without position_lps_mm (not written by flatten): exit 3.
TEST(RegisterCli, FlatMapWithoutPositionsIsBadInput) {
  testing::TempDir tmp;
  write_pair(tmp.path());
  SyntheticPair pair = make_synthetic_pair({});
  pair.prone.flat->GetPointData()->RemoveArray("position_lps_mm");
  write_run_dir(pair.prone, tmp / "prone");
  expect_one_error_line(run_register({tmp.str("supine"), tmp.str("prone"), "-o", tmp.str("out")}), 3,
                        "position_lps_mm");
}

// Parameters out of range or an unknown orientation: exit 2 and nothing written.
TEST(RegisterCli, InvalidParametersAreUsageErrors) {
  testing::TempDir tmp;
  write_pair(tmp.path());
  expect_one_error_line(run_register({tmp.str("supine"), tmp.str("prone"), "-o", tmp.str("out"), "--bin-mm", "0"}),
                        2, "--bin-mm");
  expect_one_error_line(
      run_register({tmp.str("supine"), tmp.str("prone"), "-o", tmp.str("out"), "--orientation", "sideways"}), 2,
      "--orientation");
  expect_one_error_line(run_register({tmp.str("supine"), "-o", tmp.str("out")}), 2, "PRONE_RUN_DIR");
  EXPECT_FALSE(fs::exists(tmp / "out"));
}

}  // namespace
}  // namespace cf

namespace cf {
namespace {

// The review page of a synthetic pair (no CT, no colon image): one row per pair of the JSON with
// both candidates' ids, and for every one-scan-only candidate the other scan's panel recorded at
// register's mapping of its point (within 1 mm); --no-review writes no page.
TEST(RegisterReview, SyntheticPairPageListsPairsAndCheckHerePanels) {
  testing::TempDir tmp;
  write_pair(tmp.path());
  const Result r = run_register({tmp.str("supine"), tmp.str("prone"), "-o", tmp.str("out"), "-q"});
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json page = report_page_data(tmp / "out/report.html");
  ASSERT_TRUE(page.is_object());
  const nlohmann::json cands = read_json_file(tmp / "out/registration.json")["candidates"];
  ASSERT_EQ(page["pairs"].size(), cands["pairs"].size());
  for (std::size_t i = 0; i < cands["pairs"].size(); ++i) {
    EXPECT_EQ(page["pairs"][i]["supine"]["key"], "P" + std::to_string(cands["pairs"][i]["supine_id"].get<int>()));
    EXPECT_EQ(page["pairs"][i]["prone"]["key"], "P" + std::to_string(cands["pairs"][i]["prone_id"].get<int>()));
  }
  const ColonScan sup = read_run_dir(tmp / "supine"), pro = read_run_dir(tmp / "prone");
  ColonRegistration reg(sup, pro);
  reg.run();
  ASSERT_EQ(page["singles"].size(), reg.matching().supine_only.size() + reg.matching().prone_only.size());
  ASSERT_GE(page["singles"].size(), 1u);
  for (const auto& single : page["singles"]) {
    const bool supine = single["scan"] == "supine";
    const int id = std::stoi(single["finding"]["key"].get<std::string>().substr(1));
    Eigen::Vector3d p = Eigen::Vector3d::Constant(1e9);
    for (const auto& c : (supine ? sup : pro).candidates)
      if (c.id == id) p = c.lps;
    const Eigen::Vector3d want = reg.map_lps(p, supine ? Direction::kSupineToProne : Direction::kProneToSupine);
    const auto got = single["probe"]["lps_mm"].get<std::array<double, 3>>();
    EXPECT_LT((Eigen::Vector3d(got[0], got[1], got[2]) - want).norm(), 1.0) << single.dump();
  }
  const Result off = run_register({tmp.str("supine"), tmp.str("prone"), "-o", tmp.str("off"), "--no-review", "-q"});
  ASSERT_EQ(off.code, 0) << off.err;
  EXPECT_TRUE(fs::exists(tmp / "off/registration.json"));
  EXPECT_FALSE(fs::exists(tmp / "off/report.html"));
}

// A review that fails after writing its images leaves no output folder and one error line.
TEST(RegisterReview, FailingReviewLeavesNoOutput) {
  testing::TempDir tmp;
  write_pair(tmp.path());
  ::setenv("COLONFLAT_TEST_FAIL", "review", 1);
  const Result r = run_register({tmp.str("supine"), tmp.str("prone"), "-o", tmp.str("out"), "-q"});
  ::unsetenv("COLONFLAT_TEST_FAIL");
  expect_one_error_line(r, 1, "failure injected");
  EXPECT_FALSE(fs::exists(tmp / "out"));
}

}  // namespace
}  // namespace cf

namespace cf {
namespace {

// Pixels of the side-by-side image's violet "not aligned" stripes in image columns [c0, c1).
int violet_pixels(vtkImageData* img, int c0, int c1) {
  int dims[3];
  img->GetDimensions(dims);
  int n = 0;
  for (int y = 0; y < dims[1]; ++y)
    for (int x = std::max(0, c0); x < std::min(dims[0], c1); ++x) {
      const auto* p = static_cast<unsigned char*>(img->GetScalarPointer(x, y, 0));
      n += p[0] == 170 && p[1] == 90 && p[2] == 230;
    }
  return n;
}

// A quarter of the colon (125 of 500 mm) left out of the prone map: the review page names the
// stretch that could not be aligned (70 % of it or more), marks the supine polyps 20 mm or more
// inside as unaligned and pairs none of the polyps there,
// and the side-by-side image stripes those columns violet and no column of the aligned rectal part.
TEST(RegisterReview, UnalignedStretchIsShownOnPageAndImage) {
  testing::TempDir tmp;
  SyntheticPairOptions o;
  o.prone_removed = {{150, 275}};
  const SyntheticPair pair = make_synthetic_pair(o);
  write_run_dir(pair.supine, tmp / "supine");
  write_run_dir(pair.prone, tmp / "prone");
  const Result r = run_register({tmp.str("supine"), tmp.str("prone"), "-o", tmp.str("out"), "-q"});
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json page = report_page_data(tmp / "out/report.html");
  const auto& gaps = page["alignment"]["unaligned_mm"];
  double covered = 0;
  for (const auto& g : gaps) covered += std::max(0.0, std::min(g[1].get<double>(), 275.0) - std::max(g[0].get<double>(), 150.0));
  EXPECT_GT(covered, 0.7 * 125) << gaps.dump();
  int unaligned = 0;
  for (const auto& s : page["singles"]) unaligned += s["unaligned"].get<bool>();
  int inside = 0;  // polyps 20 mm or more inside the dropped stretch
  for (const auto& q : pair.polyps) inside += q.sigma_mm > 170 && q.sigma_mm < 255;
  EXPECT_GE(unaligned, inside);
  for (const auto& q : pair.polyps)
    for (const auto& p : page["pairs"])
      if (!q.in_prone) EXPECT_NE(p["supine"]["key"], "P" + std::to_string(q.id));
  for (const auto& p : page["pairs"]) EXPECT_EQ(p["supine"]["key"], p["prone"]["key"]);
  vtkNew<vtkPNGReader> png;
  png->SetFileName((tmp / "out/supine_prone.png").c_str());
  png->Update();
  const int left = 90;  // image margin left of s = 0 (side_by_side.cpp), 1 mm per pixel
  EXPECT_GT(violet_pixels(png->GetOutput(), left + 170, left + 255), 500);
  EXPECT_EQ(violet_pixels(png->GetOutput(), left + 10, left + 120), 0);
}

}  // namespace
}  // namespace cf
