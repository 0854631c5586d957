// `colonflat denoise` as a command: outputs, report, progress, exit codes and messages.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "bench_meshes.h"
#include "colonflat/core/mesh_io.h"
#include "colonflat/core/synthetic.h"
#include "colonflat/denoise/loops_io.h"
#include "colonflat/pipeline/dispatch.h"
#include "colonflat/testing/command.h"
#include "colonflat/testing/temp_dir.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

testing::CommandResult call(const std::vector<std::string>& args) { return testing::run_colonflat(args); }

// A genus-3 chain: genus-0 mesh, loops .vtp and a report with per-component genus, loops and times.
TEST(DenoiseCli, WritesMeshLoopsAndReport) {
  testing::TempDir dir;
  write_mesh(synthetic::to_mesh(synthetic::torus_chain(3, 3, 1, 16, 8, 10)), dir / "in.off");
  auto r = call({"denoise", dir.str("in.off"), "-o", dir.str("out.vtp"), "--loops", dir.str("loops.vtp"), "--report",
                 dir.str("report.json")});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("denoise: 3/3 handles removed"), std::string::npos) << r.err;
  auto out = load_mesh(dir / "out.vtp");
  EXPECT_EQ(out.topology.genus, 0);
  EXPECT_TRUE(out.topology.closed);
  LoopSet loops = read_loops(dir / "loops.vtp");
  ASSERT_EQ(loops.size(), 3u);
  EXPECT_EQ(loops[0].type, "handle");
  std::ifstream in(dir / "report.json");
  auto j = nlohmann::json::parse(in);
  const auto& res = j["result"];
  EXPECT_EQ(res["genus_before"], 3);
  EXPECT_EQ(res["genus_after"], 0);
  EXPECT_EQ(res["per_component"][0]["genus_before"], 3);
  EXPECT_EQ(res["loops"].size(), 3u);
  EXPECT_EQ(res["loops"][0]["vertex_count"], res["loops"][0]["vertex_ids"].size());
  EXPECT_GT(res["totals"]["loop_vertices"].get<int>(), 0);
  EXPECT_TRUE(res["time_s"].contains("loop_search"));
  EXPECT_EQ(j["parameters"]["method"], "exact");
}

// Each loop is described where a reader needs it (LPS centroid, diameter, cross-section area,
// in the report and in loops.vtp), and --strict passes when every cap is clean.
TEST(DenoiseCli, LoopDescriptionsAndStrict) {
  testing::TempDir dir;
  write_mesh(synthetic::to_mesh(synthetic::torus(3, 1, 24, 10)), dir / "in.off");
  auto r = call({"denoise", dir.str("in.off"), "-o", dir.str("out.vtp"), "--loops", dir.str("loops.vtp"), "--report",
                 dir.str("report.json"), "--strict"});
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream in(dir / "report.json");
  const auto j = nlohmann::json::parse(in);
  const auto& loop = j["result"]["loops"][0];
  // The meridian of a torus (tube radius 1, centre circle radius 3): a 10-gon of radius 1.
  const auto c = loop["centroid_lps_mm"];
  EXPECT_NEAR(std::hypot(c[0].get<double>(), c[1].get<double>()), 3.0, 1e-6);  // .off keeps ~7 digits
  EXPECT_NEAR(loop["diameter_mm"].get<double>(), 2.0, 1e-6);
  EXPECT_NEAR(loop["cross_section_area_mm2"].get<double>(), 0.5 * 10 * std::sin(2 * 3.14159265358979 / 10), 1e-6);
  EXPECT_EQ(j["result"]["totals"]["loops_with_cap_intersections"], 0);
  EXPECT_EQ(j["parameters"]["strict"], true);
  const LoopSet loops = read_loops(dir / "loops.vtp");
  ASSERT_EQ(loops.size(), 1u);
  EXPECT_NEAR(loops[0].diameter_mm, 2.0, 1e-6);
}

// A non-manifold mesh: exit 3 with one line naming the file; nothing written.
TEST(DenoiseCli, NonManifoldInputIsRefused) {
  testing::TempDir dir;
  const std::string bad = std::string(COLONFLAT_SHARED_DIR) + "/meshes/BAD_beast.off";
  auto r = call({"denoise", bad, "-o", dir.str("out.vtp"), "-q"});
  EXPECT_EQ(r.code, 3);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(r.err.rfind("colonflat denoise: error: " + bad + ": not a 2-manifold", 0), 0u) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out.vtp"));
}

// Invalid parameters: exit 2, the reason, nothing written.
TEST(DenoiseCli, InvalidParametersAreUsageErrors) {
  testing::TempDir dir;
  write_mesh(synthetic::to_mesh(synthetic::torus(3, 1, 12, 8)), dir / "in.off");
  auto a = call({"denoise", dir.str("in.off"), "-o", dir.str("out.vtp"), "--target-genus", "-1"});
  EXPECT_EQ(a.code, 2);
  EXPECT_NE(a.err.find("--target-genus must be >= 0 (got -1)"), std::string::npos) << a.err;
  auto b = call({"denoise", dir.str("in.off"), "-o", dir.str("out.vtp"), "--method", "paper", "--policy", "fill"});
  EXPECT_EQ(b.code, 2);
  EXPECT_NE(b.err.find("needs --method exact"), std::string::npos) << b.err;
  auto c = call({"denoise", dir.str("in.off"), "-o", dir.str("out.vtp"), "--max-loop-length", "0"});
  EXPECT_EQ(c.code, 2);
  auto d = call({"denoise", dir.str("in.off"), "-o", dir.str("out.vtp"), "--method", "paper", "--remove-stumps", "20"});
  EXPECT_EQ(d.code, 2);
  EXPECT_NE(d.err.find("--remove-stumps needs --method exact"), std::string::npos) << d.err;
  auto e = call({"denoise", dir.str("in.off"), "-o", dir.str("out.vtp"), "--remove-stumps", "-1"});
  EXPECT_EQ(e.code, 2);
  EXPECT_FALSE(fs::exists(dir / "out.vtp"));
}

// --help lists the parameters with defaults and units.
TEST(DenoiseCli, HelpListsParameters) {
  auto r = call({"denoise", "--help"});
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("--max-loop-length"), std::string::npos);
  EXPECT_NE(r.out.find("[mm] (default inf"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("exact|paper"), std::string::npos);
  EXPECT_NE(r.out.find("--loops"), std::string::npos);
  EXPECT_NE(r.out.find("--remove-stumps"), std::string::npos);
}

// The paper method through the command marks the separating neck loop in the loops file.
TEST(DenoiseCli, PaperMarksSeparatingLoops) {
  testing::TempDir dir;
  write_mesh(synthetic::to_mesh(synthetic::torus_chain(2, 3, 1, 16, 8, 10)), dir / "in.vtp");
  auto r = call({"denoise", dir.str("in.vtp"), "-o", dir.str("out.vtp"), "--method", "paper", "--loops",
                 dir.str("loops.vtp"), "-q"});
  ASSERT_EQ(r.code, 0) << r.err;
  LoopSet loops = read_loops(dir / "loops.vtp");
  ASSERT_FALSE(loops.empty());
  EXPECT_TRUE(loops[0].separating);
}

// --strict on an input whose handle cannot be capped cleanly (a ring inside the torus tube links
// every meridian, a ring through its hole every loop crossing them): exit 1, one error line naming the input, no output written.
TEST(DenoiseCli, StrictFailsWhenNoCleanCapExists) {
  testing::TempDir dir;
  write_mesh(bench::blocked_torus(bench::Blocker::kCoreAndLinkRings), dir / "in.off");
  auto r = call({"denoise", dir.str("in.off"), "-o", dir.str("out.vtp"), "--report", dir.str("report.json"), "--strict",
                 "-q"});
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.err.rfind("colonflat denoise: error: ", 0), 0u) << r.err;  // -q: nothing but the error line
  EXPECT_NE(r.err.find("--strict"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.rfind("colonflat denoise: error: " + dir.str("in.off") + ": --strict: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("intersect"), std::string::npos) << r.err;
  std::size_t error_lines = 0;
  std::istringstream lines(r.err);
  for (std::string line; std::getline(lines, line);) error_lines += !line.empty();
  EXPECT_EQ(error_lines, 1u) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out.vtp"));
  EXPECT_FALSE(fs::exists(dir / "report.json"));
  // Without --strict the same input is denoised and the intersections are reported.
  auto ok = call({"denoise", dir.str("in.off"), "-o", dir.str("out.vtp"), "--report", dir.str("report.json")});
  ASSERT_EQ(ok.code, 0) << ok.err;
  EXPECT_NE(ok.err.find("WARNING"), std::string::npos) << ok.err;
}

}  // namespace
}  // namespace cf
