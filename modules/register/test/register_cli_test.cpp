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

#include "colonflat/register/register_tool.h"
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
