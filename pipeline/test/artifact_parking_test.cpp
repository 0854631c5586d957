// `colonflat run` holds the CT in 16 bits and the lumen mask in one bit per voxel from reconstruct
// to the review report (artifact_parking.h): the run report says so, and the report built from the
// run's memory (both expanded back) equals, file for file, the one `colonflat report` builds from
// the files.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "colonflat/core/stage.h"
#include "colonflat/pipeline/registry.h"
#include "colonflat/testing/command.h"
#include "colonflat/testing/files.h"
#include "colonflat/testing/temp_dir.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

// The CT and the mask are parked after reconstruct (the last stage that reads them), the
// Segmentation montages are drawn beside the stages, and every image of report_files/ made from the run's memory is
// byte-identical to those `colonflat report` makes from the files.
TEST(ArtifactParking, CtAndMaskHeldCompactAndRestoredExactlyForTheReport) {
  for (const char* s : {"segment", "reconstruct", "denoise", "flatten", "render"})
    if (!find_stage(s)) GTEST_SKIP() << "this build has no " << s << " stage";
  testing::TempDir dir;
  auto ph = testing::run_colonflat({"phantom", "--size", "small", "--seed", "2", "-o", dir.str("ph"), "-q"});
  ASSERT_EQ(ph.code, 0) << ph.err;
  auto run = testing::run_colonflat({"run", dir.str("ph/ct.nrrd"), "-o", dir.str("out"), "-q", "--set",
                                     "render.snapshots=false"});
  ASSERT_EQ(run.code, 0) << run.err;
  const nlohmann::json report = read_json_file(dir / "out" / "run_report.json");
  ASSERT_TRUE(report.contains("held_compact")) << report.dump(1).substr(0, 2000);
  ASSERT_EQ(report["held_compact"].size(), 2u);
  std::set<std::string> held;
  for (const auto& h : report["held_compact"]) {
    held.insert(h["artifact"].get<std::string>());
    EXPECT_EQ(h["after_stage"], "reconstruct");
  }
  EXPECT_EQ(held, (std::set<std::string>{"ct", "mask"}));
  bool drawn_beside = false;
  for (const auto& finisher : report["after_stages"])
    for (const auto& phase : finisher.value("phases", nlohmann::json::array()))
      drawn_beside = drawn_beside || phase.value("phase", "").find("drawn beside the stages") != std::string::npos;
  EXPECT_TRUE(drawn_beside) << report["after_stages"].dump(1);
  fs::copy(dir / "out" / "report_files", dir / "from_memory", fs::copy_options::recursive);
  const std::string page = testing::slurp(dir / "out" / "report.html");
  auto again = testing::run_colonflat({"report", dir.str("out"), "-q"});
  ASSERT_EQ(again.code, 0) << again.err;
  std::size_t images = 0, montages = 0;
  for (const auto& e : fs::directory_iterator(dir / "from_memory")) {
    if (e.path().extension() != ".png") continue;
    ++images;
    montages += e.path().filename().string().rfind("seg_", 0) == 0;
    EXPECT_EQ(testing::slurp(e.path()), testing::slurp(dir / "out" / "report_files" / e.path().filename()))
        << e.path().filename();
  }
  EXPECT_GT(images, 10u);  // CT planes and segmentation montages at least
  EXPECT_GE(montages, 12u);  // at least 4 slices in each of the 3 planes
}

}  // namespace
}  // namespace cf
