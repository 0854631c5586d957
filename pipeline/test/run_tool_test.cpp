// `colonflat run`: --from/--to, --debug-dir, --params-in/--params-out, --set, the run report, and
// its errors (fast: starts at the denoise stage on a synthetic mesh).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "colonflat/core/mesh_io.h"
#include "colonflat/core/synthetic.h"
#include "colonflat/pipeline/registry.h"
#include "colonflat/testing/command.h"
#include "colonflat/core/stage.h"
#include "colonflat/testing/temp_dir.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

class RunTool : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!find_stage("denoise")) GTEST_SKIP() << "this build has no denoise stage";
    write_mesh(synthetic::to_mesh(synthetic::torus_chain(3, 3, 1, 16, 8, 10)), dir_ / "chain.vtp");
  }
  testing::TempDir dir_;
};

// --from/--to run one stage on a mesh; outputs, run report (units, space) and debug folder appear.
TEST_F(RunTool, FromToWithDebugDirAndReport) {
  auto r = testing::run_colonflat({"run", dir_.str("chain.vtp"), "--from", "denoise", "--to", "denoise", "-o",
                                   dir_.str("out"), "--debug-dir", dir_.str("dbg"), "--params-out",
                                   dir_.str("params.json")});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(load_mesh(dir_ / "out" / "denoised.vtp").topology.genus, 0);
  EXPECT_TRUE(fs::exists(dir_ / "out" / "loops.vtp"));
  auto rep = read_json_file(dir_ / "out" / "run_report.json");
  EXPECT_EQ(rep["units"], "mm");
  EXPECT_EQ(rep["coordinate_system"], "LPS");
  ASSERT_EQ(rep["stages"].size(), 1u);
  EXPECT_EQ(rep["stages"][0]["stage"], "denoise");
  EXPECT_EQ(rep["stages"][0]["result"]["genus_after"], 0);
  EXPECT_TRUE(rep["stages"][0].contains("peak_memory_mib"));
  EXPECT_TRUE(fs::exists(dir_ / "out" / "run_report.txt"));
  // The debug folder holds the stage's outputs and its JSON.
  bool found = false;
  for (const auto& e : fs::directory_iterator(dir_ / "dbg"))
    if (e.path().filename().string().find("_denoise") != std::string::npos) {
      found = true;
      EXPECT_TRUE(fs::exists(e.path() / "stage.json"));
      EXPECT_TRUE(fs::exists(e.path() / "denoised.vtp"));
    }
  EXPECT_TRUE(found);
  // --params-out lists the stage's parameters with their values.
  auto params = read_json_file(dir_ / "params.json");
  EXPECT_EQ(params["denoise"]["method"], "exact");
  EXPECT_NE(r.err.find("[1/1] denoise"), std::string::npos) << r.err;
}

// --set and --params-in change parameters (target genus 2 leaves one loop); typos are errors.
TEST_F(RunTool, SetAndParamsIn) {
  auto a = testing::run_colonflat({"run", dir_.str("chain.vtp"), "--from", "denoise", "--to", "denoise", "-o",
                                   dir_.str("a"), "--set", "denoise.target-genus=2", "-q"});
  ASSERT_EQ(a.code, 0) << a.err;
  EXPECT_EQ(load_mesh(dir_ / "a" / "denoised.vtp").topology.genus, 2);
  std::ofstream(dir_ / "p.json") << R"({"denoise": {"target-genus": 1}})";
  auto b = testing::run_colonflat({"run", dir_.str("chain.vtp"), "--from", "denoise", "--to", "denoise", "-o",
                                   dir_.str("b"), "--params-in", dir_.str("p.json"), "-q"});
  ASSERT_EQ(b.code, 0) << b.err;
  EXPECT_EQ(load_mesh(dir_ / "b" / "denoised.vtp").topology.genus, 1);
  auto typo = testing::run_colonflat({"run", dir_.str("chain.vtp"), "--from", "denoise", "--to", "denoise", "-o",
                                      dir_.str("c"), "--set", "denoise.target-genes=1", "-q"});
  EXPECT_EQ(typo.code, 2);
  EXPECT_NE(typo.err.find("unknown parameter 'target-genes'"), std::string::npos) << typo.err;
  EXPECT_FALSE(fs::exists(dir_ / "c"));
}

// The example parameter files shipped in data/params are accepted by `run`.
TEST_F(RunTool, ShippedParameterFilesAreValid) {
  for (const char* f : {"partial_denoise.json", "paper_method.json", "remove_stumps.json"}) {
    auto r = testing::run_colonflat({"run", dir_.str("chain.vtp"), "--from", "denoise", "--to", "denoise", "-o",
                                     dir_.str(std::string("out_") + f), "--params-in",
                                     std::string(COLONFLAT_SOURCE_DIR) + "/data/params/" + f, "-q"});
    EXPECT_EQ(r.code, 0) << f << ": " << r.err;
  }
}

// Errors: unknown stage, --from after --to, a parameter out of range; nothing is written.
TEST_F(RunTool, UsageErrors) {
  auto a = testing::run_colonflat({"run", dir_.str("chain.vtp"), "--from", "polish", "-o", dir_.str("x")});
  EXPECT_EQ(a.code, 2);
  EXPECT_NE(a.err.find("unknown or unavailable stage 'polish'"), std::string::npos) << a.err;
  if (find_stage("reconstruct")) {
    auto b = testing::run_colonflat({"run", dir_.str("chain.vtp"), "--from", "denoise", "--to", "reconstruct", "-o",
                                     dir_.str("x")});
    EXPECT_EQ(b.code, 2);
  }
  auto c = testing::run_colonflat({"run", dir_.str("chain.vtp"), "--from", "denoise", "--to", "denoise", "-o",
                                   dir_.str("x"), "--set", "denoise.ring-pull=0.9"});
  EXPECT_EQ(c.code, 2);
  EXPECT_NE(c.err.find("--ring-pull must be <= 0.5"), std::string::npos) << c.err;
  auto d = testing::run_colonflat({"run", dir_.str("missing.vtp"), "--from", "denoise", "-o", dir_.str("x")});
  EXPECT_EQ(d.code, 3);
  EXPECT_FALSE(fs::exists(dir_ / "x"));
}

}  // namespace
}  // namespace cf
