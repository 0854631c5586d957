// The stand-alone command generated from a stage's declaration: help, ranges, JSON parameters,
// atomic outputs and refusal to overwrite the input.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "colonflat/core/mesh_artifact.h"
#include "colonflat/core/mesh_io.h"
#include "colonflat/core/stage.h"
#include "colonflat/core/synthetic.h"
#include "colonflat/testing/temp_dir.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

// A tiny stage for the test: scales a mesh.
struct ScaleOptions {
  double factor = 2.0;  // unitless
  std::string mode = "uniform";
};
class ScaleStage : public StageWithOptions<ScaleOptions> {
 public:
  const StageSpec& spec() const override {
    static const StageSpec s{"scale", "scales a mesh",
                             {{"mesh", &mesh_artifact(), "input mesh", "in.vtp"}},
                             {{"scaled", &mesh_artifact(), "scaled mesh", "scaled.vtp"}}};
    return s;
  }
  void run(ArtifactBag& bag, RunContext& ctx) override {
    Mesh m = bag.get<Mesh>("mesh");
    for (auto v : m.vertices()) m.point(v) *= opts_.factor;
    ctx.report["vertices"] = m.n_vertices();
    bag.put("scaled", std::move(m));
  }

 protected:
  const ParamTable<ScaleOptions>& table() const override {
    static const ParamTable<ScaleOptions> t = [] {
      ParamTable<ScaleOptions> t;
      t.real("factor", &ScaleOptions::factor, "", "scale factor", 0.001, 1000);
      t.choice("mode", &ScaleOptions::mode, {"uniform", "other"}, "mode");
      return t;
    }();
    return t;
  }
};

struct Result {
  int code;
  std::string out, err;
};

class StageToolTest : public ::testing::Test {
 protected:
  void SetUp() override {
    tmp_ = std::make_unique<testing::TempDir>();
    dir_ = tmp_->path();
    write_mesh(synthetic::to_mesh(synthetic::sphere(1, 8, 4)), dir_ / "in.off");
  }
  Result call(const std::vector<std::string>& args) {
    auto tool = make_stage_tool([] { return std::make_unique<ScaleStage>(); });
    std::ostringstream out, err;
    int code = tool->run(args, out, err);
    return {code, out.str(), err.str()};
  }
  std::string p(const std::string& n) const { return (dir_ / n).string(); }
  std::unique_ptr<testing::TempDir> tmp_;
  fs::path dir_;
};

// --help lists each parameter with its default and range, and the ports.
TEST_F(StageToolTest, HelpComesFromDeclaration) {
  auto r = call({"--help"});
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("--factor"), std::string::npos);
  EXPECT_NE(r.out.find("(default 2; range [0.001, 1000])"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("uniform|other"), std::string::npos);
  EXPECT_NE(r.out.find("--report"), std::string::npos);
}

// Running writes the output and the report; the report holds parameters and results.
TEST_F(StageToolTest, RunsAndReports) {
  auto r = call({p("in.off"), "-o", p("out.vtp"), "--factor", "3", "--report", p("r.json"), "-q"});
  ASSERT_EQ(r.code, 0) << r.err;
  auto m = load_mesh(p("out.vtp"));
  EXPECT_NEAR(m.mesh.point(Mesh::VertexHandle(0)).norm(), 3.0, 1e-9);
  std::ifstream in(p("r.json"));
  auto j = nlohmann::json::parse(in);
  EXPECT_EQ(j["parameters"]["factor"], 3.0);
  EXPECT_EQ(j["result"]["vertices"], m.mesh.n_vertices());
}

// A parameter out of range: exit 2, one error line, no output written.
TEST_F(StageToolTest, OutOfRangeIsUsageErrorAndWritesNothing) {
  auto r = call({p("in.off"), "-o", p("out.vtp"), "--factor", "0"});
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "colonflat scale: error: --factor must be >= 0.001 (got 0)\n");
  EXPECT_FALSE(fs::exists(p("out.vtp")));
  auto bad_choice = call({p("in.off"), "-o", p("out.vtp"), "--mode", "weird"});
  EXPECT_EQ(bad_choice.code, 2);
}

// A missing input: exit 3 naming the file; nothing written.
TEST_F(StageToolTest, MissingInputIsBadInput) {
  auto r = call({p("none.off"), "-o", p("out.vtp")});
  EXPECT_EQ(r.code, 3);
  EXPECT_EQ(r.err, "colonflat scale: error: " + p("none.off") + ": no such file\n");
  EXPECT_FALSE(fs::exists(p("out.vtp")));
}

// Output equal to input is refused before anything runs.
TEST_F(StageToolTest, RefusesToOverwriteInput) {
  auto r = call({p("in.off"), "-o", p("in.off")});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("would overwrite the input"), std::string::npos);
}

// --params-out then --params-in reproduces the parameters; command-line values win over the file.
TEST_F(StageToolTest, ParamsJsonRoundTrip) {
  ASSERT_EQ(call({p("in.off"), "-o", p("a.vtp"), "--factor", "5", "--params-out", p("params.json"), "-q"}).code, 0);
  ASSERT_EQ(call({p("in.off"), "-o", p("b.vtp"), "--params-in", p("params.json"), "--report", p("rb.json"), "-q"}).code, 0);
  std::ifstream rb(p("rb.json"));
  EXPECT_EQ(nlohmann::json::parse(rb)["parameters"]["factor"], 5.0);
  ASSERT_EQ(call({p("in.off"), "-o", p("c.vtp"), "--params-in", p("params.json"), "--factor", "7", "--report",
                  p("rc.json"), "-q"}).code, 0);
  std::ifstream rc(p("rc.json"));
  EXPECT_EQ(nlohmann::json::parse(rc)["parameters"]["factor"], 7.0);
  std::ofstream(p("typo.json")) << R"({"scale": {"facter": 2}})";
  auto r = call({p("in.off"), "-o", p("d.vtp"), "--params-in", p("typo.json")});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("unknown parameter 'facter'"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace cf
