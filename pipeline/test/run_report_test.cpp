// `colonflat run` through render and its finisher, the review report (issue 15): the report is
// built from the run's memory and equals the one `colonflat report` builds from the files; a
// failing report leaves no run output; every stage prints its phases unless -q (issue 14).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>

#include <nlohmann/json.hpp>

#include "colonflat/core/stage.h"
#include "colonflat/pipeline/registry.h"
#include "colonflat/testing/command.h"
#include "colonflat/testing/files.h"
#include "colonflat/testing/temp_dir.h"
#include "colonflat/volume/volume_io.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

// A lumen mask of a closed tube (radius 10 mm, 120 mm long, 1 mm voxels) with a 9 mm polyp: a
// ball of wall pushed into the lumen half-way along.
void write_tube_mask(const fs::path& file) {
  auto m = MaskImage::New();
  MaskImage::RegionType r;
  r.SetSize({{150, 32, 32}});
  m->SetRegions(r);
  MaskImage::PointType origin;
  origin[0] = -75, origin[1] = -16, origin[2] = -16;
  m->SetOrigin(origin);
  m->Allocate(true);
  for (int k = 0; k < 32; ++k)
    for (int j = 0; j < 32; ++j)
      for (int i = 0; i < 150; ++i) {
        const double x = i - 75.0, y = j - 16.0, z = k - 16.0;
        const double along = std::max(0.0, std::abs(x) - 60.0);  // rounded ends
        const bool tube = along * along + y * y + z * z <= 100;
        const bool polyp = (x - 5) * (x - 5) + (y - 10) * (y - 10) + z * z <= 4.5 * 4.5;
        if (tube && !polyp) m->SetPixel({{i, j, k}}, 1);
      }
  write_mask(m, file);
}

using testing::slurp;

// The JSON the page embeds (window.REPORT = {...};).
nlohmann::json page_data(const fs::path& html) {
  const std::string text = slurp(html);
  const auto at = text.find("window.REPORT = ");
  if (at == std::string::npos) return nullptr;
  std::istringstream in(text.substr(at + 16));
  nlohmann::json j;
  in >> j;  // reads one value, ignores what follows
  return j;
}

using testing::listing;

class RunReport : public ::testing::Test {
 protected:
  void SetUp() override {
    for (const char* s : {"reconstruct", "denoise", "flatten", "render"})
      if (!find_stage(s)) GTEST_SKIP() << "this build has no " << s << " stage";
    write_tube_mask(dir_ / "tube.nrrd");
  }
  testing::CommandResult run(const std::string& out, bool quiet) {
    std::vector<std::string> args = {"run", dir_.str("tube.nrrd"), "--from", "reconstruct", "-o", dir_.str(out),
                                     "--set", "render.snapshots=false"};
    if (quiet) args.push_back("-q");
    return testing::run_colonflat(args);
  }
  testing::TempDir dir_;
};

// The page the run builds from its memory holds the same data as the page `colonflat report`
// builds from the run's files (flat map, mask views, lookup grid, findings, summary), and the
// run report records the report's time after the stages'.
TEST_F(RunReport, BuiltFromMemoryEqualsReportFromFiles) {
  const auto r = run("out", true);
  ASSERT_EQ(r.code, 0) << r.err;
  nlohmann::json memory = page_data(dir_ / "out" / "report.html");
  ASSERT_TRUE(memory.is_object());
  const auto again = testing::run_colonflat({"report", dir_.str("out"), "-q"});
  ASSERT_EQ(again.code, 0) << again.err;
  nlohmann::json files = page_data(dir_ / "out" / "report.html");
  ASSERT_TRUE(files.is_object());
  EXPECT_TRUE(memory.contains("lookup") && memory.contains("stacks") && memory.contains("image"));
  EXPECT_TRUE(memory["ct"].value("is_mask", false));  // a run from a mask shows the mask, not a CT
  // The totals differ: the file's run report includes the report itself.
  for (auto* j : {&memory, &files}) (*j)["summary"].erase("total_time_s"), (*j)["summary"].erase("peak_memory_mib");
  EXPECT_EQ(memory, files) << "differences: " << nlohmann::json::diff(memory, files).dump();
  const nlohmann::json report = read_json_file(dir_ / "out" / "run_report.json");
  ASSERT_EQ(report["after_stages"].size(), 1u);
  EXPECT_EQ(report["after_stages"][0]["step"], "report");
  EXPECT_GT(report["total_time_s"].get<double>(), report["stages_time_s"].get<double>());
  EXPECT_NE(slurp(dir_ / "out" / "run_report.txt").find("after the stages"), std::string::npos);
}

// Without -q every stage prints one "stage: phase N s" line per phase, the report included; -q
// prints nothing at all.
TEST_F(RunReport, PhaseLinesUnlessQuiet) {
  const auto loud = run("loud", false);
  ASSERT_EQ(loud.code, 0) << loud.err;
  for (const char* line : {"reconstruct: surface extraction", "reconstruct: smoothing", "denoise: topology analysis",
                           "flatten: conformal map", "flatten: centreline", "render: colon image and candidates",
                           "report: run data from memory", "report: page and Slicer files"})
    EXPECT_TRUE(std::regex_search(loud.err, std::regex(std::string("(^|\n)") + line + " [0-9]+\\.[0-9]+ s\n")))
        << line << " missing in:\n" << loud.err;
  const nlohmann::json report = read_json_file(dir_ / "loud" / "run_report.json");
  for (const auto& stage : report["stages"]) EXPECT_FALSE(stage["phases"].empty()) << stage["stage"];
  const auto quiet = run("quiet", true);
  ASSERT_EQ(quiet.code, 0) << quiet.err;
  EXPECT_EQ(quiet.err, "");
  EXPECT_EQ(quiet.out, "");
  // The same in a stand-alone stage command.
  const auto alone = testing::run_colonflat({"flatten", dir_.str("loud/denoised.vtp"), "-o", dir_.str("f.vtp")});
  ASSERT_EQ(alone.code, 0) << alone.err;
  EXPECT_TRUE(std::regex_search(alone.err, std::regex("(^|\n)flatten: conformal map [0-9]+\\.[0-9]+ s\n"))) << alone.err;
  const auto alone_quiet =
      testing::run_colonflat({"flatten", dir_.str("loud/denoised.vtp"), "-o", dir_.str("g.vtp"), "-q"});
  ASSERT_EQ(alone_quiet.code, 0) << alone_quiet.err;
  EXPECT_EQ(alone_quiet.err, "");
}

// A report that fails (test-only fault injection, docs/pipeline.md) fails the run with one error
// line, and the run commits nothing: a fresh folder stays empty, and an earlier run's outputs in
// the folder keep their content, with no staging folder left behind.
TEST_F(RunReport, FailingReportLeavesNoRunOutput) {
  ASSERT_EQ(run("earlier", true).code, 0);
  const std::vector<std::string> before = listing(dir_ / "earlier");
  const std::string report_before = slurp(dir_ / "earlier" / "run_report.json");
  ::setenv("COLONFLAT_TEST_FAIL", "report", 1);
  const auto fresh = run("fresh", true);
  const auto earlier = run("earlier", true);
  ::unsetenv("COLONFLAT_TEST_FAIL");
  for (const auto* r : {&fresh, &earlier}) {
    EXPECT_EQ(r->code, 1);
    EXPECT_EQ(std::count(r->err.begin(), r->err.end(), '\n'), 1) << r->err;
    EXPECT_EQ(r->err.rfind("colonflat run: error: ", 0), 0u) << r->err;
    EXPECT_NE(r->err.find("COLONFLAT_TEST_FAIL"), std::string::npos) << r->err;
  }
  EXPECT_EQ(listing(dir_ / "fresh"), std::vector<std::string>{});
  EXPECT_EQ(listing(dir_ / "earlier"), before);
  EXPECT_EQ(slurp(dir_ / "earlier" / "run_report.json"), report_before);
}

}  // namespace
}  // namespace cf
