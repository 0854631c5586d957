// `colonflat info`: the report on good meshes, diagnoses and exit codes on bad ones.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "colonflat/core/mesh_io.h"
#include "colonflat/core/synthetic.h"
#include "colonflat/testing/temp_dir.h"
#include "colonflat/pipeline/dispatch.h"
#include "colonflat/testing/command.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

testing::CommandResult call(const std::vector<std::string>& args) { return testing::run_colonflat(args); }
std::string shared(const std::string& name) { return std::string(COLONFLAT_SHARED_DIR) + "/meshes/" + name; }

// A valid closed mesh: exit 0, genus and flags in the text report, nothing on stderr.
TEST(InfoCli, ValidMeshReportsGenus) {
  auto r = call({"info", shared("double_torus.off")});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("genus           2"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("closed          yes"), std::string::npos);
  EXPECT_TRUE(r.err.empty()) << r.err;
}

// --json gives per-component genus and the flags; several components are summed.
TEST(InfoCli, JsonReportPerComponent) {
  auto r = call({"info", "--json", shared("ct_head_skin_mc.off")});
  EXPECT_EQ(r.code, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["topology"]["components"], 33);
  EXPECT_EQ(j["topology"]["genus"], 32);
  EXPECT_EQ(j["topology"]["per_component"][0]["genus"], 28);
  EXPECT_EQ(j["topology"]["euler_characteristic"], 2);
  EXPECT_TRUE(j["valid"].get<bool>());
}

// Each BAD_ mesh: exit 3 and a single error line naming the file and its defect.
TEST(InfoCli, BadMeshesExitThreeWithDiagnosis) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"BAD_eight_open.off", "96 boundary edges"},
      {"BAD_eight_hole.off", "6 boundary edges in 1 boundary loop"},
      {"BAD_beast.off", "2 non-manifold edges"},
      {"BAD_heptoroid_unwelded.off", "11056 boundary edges"},
      {"BAD_happy_vrip_res3.off", "2816 non-manifold edges"}};
  for (const auto& [name, what] : cases) {
    auto r = call({"info", shared(name)});
    EXPECT_EQ(r.code, 3) << name;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.err.rfind("colonflat info: error: " + shared(name) + ": ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(what), std::string::npos) << r.err;
  }
}

// An open mesh is valid with --allow-boundary (a colon tube), a defect without.
TEST(InfoCli, AllowBoundary) {
  auto r = call({"info", "--allow-boundary", shared("BAD_eight_hole.off")});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("genus           2"), std::string::npos) << r.out;
}

// Missing file, unknown format, empty file and a usage error: exit codes 3, 3, 3, 2.
TEST(InfoCli, UnreadableInputs) {
  auto missing = call({"info", "/nonexistent/x.off"});
  EXPECT_EQ(missing.code, 3);
  EXPECT_EQ(missing.err, "colonflat info: error: /nonexistent/x.off: no such file\n");
  testing::TempDir dir;
  const fs::path tmp = dir.path();
  std::ofstream(tmp / "a.txt") << "hello";
  std::ofstream(tmp / "e.ply") << "";
  EXPECT_EQ(call({"info", (tmp / "a.txt").string()}).code, 3);
  auto empty = call({"info", (tmp / "e.ply").string()});
  EXPECT_EQ(empty.code, 3);
  EXPECT_NE(empty.err.find("empty file"), std::string::npos);
  EXPECT_EQ(call({"info"}).code, 2);
  EXPECT_EQ(call({"info", "--bogus", shared("torus.off")}).code, 2);
}

// The input file is never modified by info (same size and bytes before and after).
TEST(InfoCli, InputUntouched) {
  testing::TempDir dir;
  const fs::path tmp = dir.path();
  write_mesh(synthetic::to_mesh(synthetic::torus(3, 1, 8, 6)), tmp / "t.off");
  std::ifstream a(tmp / "t.off");
  const std::string before((std::istreambuf_iterator<char>(a)), {});
  EXPECT_EQ(call({"info", (tmp / "t.off").string()}).code, 0);
  std::ifstream b(tmp / "t.off");
  EXPECT_EQ(before, std::string((std::istreambuf_iterator<char>(b)), {}));
  EXPECT_EQ(std::distance(fs::directory_iterator(tmp), fs::directory_iterator()), 1);
}

}  // namespace
}  // namespace cf

#if __has_include("colonflat/volume/volume_io.h")
namespace cf {
namespace {
// `colonflat info VOLUME` reports the real head CT's size and spacing (single-file and detached NRRD).
TEST(InfoCli, VolumeInfo) {
  const std::string dir = std::string(COLONFLAT_SHARED_DIR) + "/ct/vtk_headsq_quarter_ct_head/";
  auto r = call({"info", "--json", dir + "headsq_quarter.nrrd"});
  ASSERT_EQ(r.code, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.dump().find("93") != std::string::npos, true) << r.out;
  EXPECT_NE(r.out.find("3.2"), std::string::npos) << r.out;
  auto missing = call({"info", dir + "nope.nrrd"});
  EXPECT_EQ(missing.code, 3);
  EXPECT_NE(missing.err.find("nope.nrrd"), std::string::npos);
}
}  // namespace
}  // namespace cf
#endif
