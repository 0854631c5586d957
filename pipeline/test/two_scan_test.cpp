// `colonflat run SUPINE --prone PRONE -o OUT` (issue 17): the two scans of one patient run into
// OUT/supine and OUT/prone, then `register` of the two into OUT/registration.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>

#include <nlohmann/json.hpp>

#include "colonflat/core/stage.h"
#include "colonflat/pipeline/registry.h"
#include "colonflat/testing/command.h"
#include "colonflat/testing/temp_dir.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

bool has_tool(const std::string& name) {
  for (const auto& t : registered_module_tools())
    if (t->name() == name) return true;
  return false;
}

class RunTwoScans : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!has_tool("phantom") || !has_tool("register") || !find_stage("render"))
      GTEST_SKIP() << "this build lacks the phantom, register or render step";
  }
  testing::TempDir dir_;
};

// A small phantom pair (same seed, supine and prone) runs end to end: both run folders (with
// their review pages), the registration files, a length map that keeps the order of the colon
// and covers most of both colons, and nothing on stderr with -q.
TEST_F(RunTwoScans, SmallPhantomPairRunsBothAndRegisters) {
  for (const char* position : {"supine", "prone"}) {
    const auto p = testing::run_colonflat({"phantom", "-o", dir_.str(position), "--seed", "2", "--size", "small",
                                           "--position", position, "-q"});
    ASSERT_EQ(p.code, 0) << p.err;
  }
  const auto r = testing::run_colonflat({"run", dir_.str("supine/ct.nrrd"), "--prone", dir_.str("prone/ct.nrrd"), "-o",
                                         dir_.str("out"), "--set", "render.snapshots=false", "-q"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  for (const char* f : {"supine/flat.vtp", "supine/report.html", "prone/flat.vtp", "prone/candidates.json",
                        "registration/registration.json", "registration/supine_prone.png",
                        "registration/supine_to_prone.vtp", "registration/prone_to_supine.vtp"})
    EXPECT_TRUE(fs::exists(dir_ / "out" / f)) << f;
  const nlohmann::json reg = read_json_file(dir_ / "out" / "registration" / "registration.json");
  const auto& knots = reg["length_alignment"]["knots"];
  ASSERT_GE(knots.size(), 10u) << reg["length_alignment"].dump();
  double last_supine = -1, last_prone = -1e9;
  for (const auto& k : knots) {
    EXPECT_GT(k["supine_mm"].get<double>(), last_supine);
    EXPECT_GT(k["prone_mm"].get<double>(), last_prone);  // the map keeps the order along the colon
    last_supine = k["supine_mm"].get<double>(), last_prone = k["prone_mm"].get<double>();
  }
  const double supine_length = reg["supine"]["length_mm"].get<double>();
  const double prone_length = reg["prone"]["length_mm"].get<double>();
  EXPECT_GT(last_supine, 0.8 * supine_length);
  EXPECT_NEAR(prone_length, supine_length, 0.2 * supine_length);  // the same colon, deformed
}

// The prone scan given as INPUT too, or a run that stops before render, is refused before any
// work with one error line, and nothing is written.
TEST_F(RunTwoScans, InvalidPairsRefusedBeforeWork) {
  std::ofstream(dir_ / "ct.nrrd") << "not read: refused first";
  for (const std::vector<std::string>& extra : {std::vector<std::string>{"--prone", dir_.str("ct.nrrd")},
                                                std::vector<std::string>{"--prone", dir_.str("ct.nrrd"), "--to", "flatten"}}) {
    std::vector<std::string> args = {"run", dir_.str("ct.nrrd"), "-o", dir_.str("out"), "-q"};
    args.insert(args.end(), extra.begin(), extra.end());
    const auto r = testing::run_colonflat(args);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.err.rfind("colonflat run: error: ", 0), 0u) << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "out"));
  }
}

}  // namespace
}  // namespace cf
