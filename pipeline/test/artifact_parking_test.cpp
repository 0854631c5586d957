// `colonflat run` holds the CT in 16 bits from segment's crop and the lumen mask in one bit per
// voxel from reconstruct to the review report, and the surfaces before and after denoising as triangle lists from denoise
// on (artifact_parking.h): the run report says so, the report built from the run's memory (CT and
// mask expanded back) equals, file for file, the one `colonflat report` builds from the files, and
// the mesh files and the flat map equal those of the stages run alone on the files.
#include <gtest/gtest.h>

#include <array>
#include <typeinfo>
#include <map>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "artifact_parking.h"
#include "colonflat/core/stage.h"
#include "colonflat/pipeline/registry.h"
#include "colonflat/testing/command.h"
#include "colonflat/testing/files.h"
#include "colonflat/testing/temp_dir.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

// A toy artifact: an int whose stand-in is its decimal string.
const ArtifactType& toy_type() {
  static const ArtifactType t{"toy", "toy", {}, {}, {},
                              [](const std::any& v) -> std::optional<std::any> { return std::to_string(std::any_cast<int>(v)); },
                              [](const std::any& v) { return std::any(std::stoi(std::any_cast<std::string>(v))); }};
  return t;
}

// A stage that only declares its ports.
class PortsOnly : public Stage {
 public:
  explicit PortsOnly(StageSpec s) : spec_(std::move(s)) {}
  const StageSpec& spec() const override { return spec_; }
  std::vector<ParamInfo> params() const override { return {}; }
  void add_cli_options(CLI::App&) override {}
  nlohmann::json params_json() const override { return nlohmann::json::object(); }
  void set_params_json(const nlohmann::json&, const std::string&) override {}
  void validate_params() const override {}
  void run(ArtifactBag&, RunContext&) override {}

 private:
  StageSpec spec_;
};

// Port `name` of the toy type; `stand_in`: the reader takes the stand-in.
Port toy(const std::string& name, bool stand_in = false) { return {name, &toy_type(), "", name, true, stand_in}; }

RunPlan plan_of(std::vector<StageSpec> specs) {
  RunPlan plan;
  for (auto& s : specs) plan.stages.push_back(std::make_unique<PortsOnly>(std::move(s)));
  return plan;
}

// Which artifacts the two calls park after each stage, in order ("stage:artifact").
std::vector<std::string> parked_by_stage(const RunPlan& plan, ArtifactBag& bag) {
  ParkedArtifacts parked;
  nlohmann::json log = nlohmann::json::array();
  for (std::size_t i = 0; i < plan.stages.size(); ++i) {
    parked.park_outputs(plan, i, bag, log);
    parked.park_unread(plan, i, bag, log);
  }
  std::vector<std::string> out;
  for (const auto& e : log) out.push_back(e["after_stage"].get<std::string>() + ":" + e["artifact"].get<std::string>());
  return out;
}

// The parking rule: an artifact is held as its stand-in once every later stage that reads it takes
// the stand-in (or none reads it), never while a later stage reads it whole or writes it; a stage's
// own output is held before it is written (park_outputs), another stage's only after (park_unread).
TEST(ArtifactParking, HeldOnceEveryLaterReaderTakesTheStandIn) {
  ArtifactBag bag;
  bag.put("x", 7);
  bag.put("y", 8);
  // A writes x; B reads x whole, writes y; C reads both as stand-ins; D reads y whole.
  const RunPlan abcd = plan_of({{"A", "", {}, {toy("x")}},
                                {"B", "", {toy("x")}, {toy("y")}},
                                {"C", "", {toy("x", true), toy("y", true)}, {}},
                                {"D", "", {toy("y")}, {}}});
  EXPECT_EQ(parked_by_stage(abcd, bag), (std::vector<std::string>{"B:x", "D:y"}));
  EXPECT_EQ(bag.get<std::string>("x"), "7");
  EXPECT_EQ(expanded<int>(bag, "y", toy_type()), 8);
  // P writes w, read later only as a stand-in: held before its file is written; not when a later
  // stage writes w again, and not before its writer when no later stage reads it (the last stage's
  // output: `colonflat run --to segment` wrote its mask from the stand-in before the volume
  // writers took one).
  ArtifactBag bag2;
  bag2.put("w", 5);
  EXPECT_EQ(parked_by_stage(plan_of({{"P", "", {}, {toy("w")}}, {"Q", "", {toy("w", true)}, {}}}), bag2),
            (std::vector<std::string>{"P:w"}));
  ArtifactBag bag3;
  bag3.put("w", 5);
  EXPECT_EQ(parked_by_stage(plan_of({{"P", "", {}, {toy("w")}}, {"Q", "", {toy("w", true)}, {toy("w")}}}), bag3),
            (std::vector<std::string>{}));
  ArtifactBag bag4;
  bag4.put("w", 5);
  EXPECT_EQ(parked_by_stage(plan_of({{"P", "", {}, {toy("w")}}}), bag4), (std::vector<std::string>{}));
  EXPECT_EQ(bag4.get<int>("w"), 5);
}

// What park_released does with `port` released by plan.stages[running]: "held" (the bag then holds
// the stand-in) or "whole".
std::string on_release(const RunPlan& plan, std::size_t running, const std::string& port = "c") {
  ArtifactBag bag;
  bag.put(port, 4);
  ParkedArtifacts parked;
  nlohmann::json log = nlohmann::json::array();
  parked.park_released(plan, running, port, bag, log);
  if (log.empty()) return bag.raw(port).type() == typeid(int) ? "whole" : "stand-in without a log";
  EXPECT_EQ(log[0]["during_stage"], plan.stages[running]->spec().name);
  return bag.raw(port).type() == typeid(std::string) ? "held" : "logged, not held";
}

// An input a stage releases while it runs (RunContext::release_input: segment's CT once its crop is
// copied) is held as its stand-in at once when every later stage reading it takes the stand-in, or
// none reads it; never when a later stage reads it whole, when this or a later stage writes it, when
// the previous stage wrote it (its files may still be being written), or when it is not an input.
TEST(ArtifactParking, ReleasedInputHeldWhileItsStageRuns) {
  EXPECT_EQ(on_release(plan_of({{"S", "", {toy("c")}, {toy("m")}}, {"R", "", {toy("m"), toy("c", true)}, {}}}), 0), "held");
  EXPECT_EQ(on_release(plan_of({{"S", "", {toy("c")}, {toy("m")}}}), 0), "held");
  EXPECT_EQ(on_release(plan_of({{"S", "", {toy("c")}, {toy("m")}}, {"R", "", {toy("m"), toy("c")}, {}}}), 0), "whole");
  EXPECT_EQ(on_release(plan_of({{"S", "", {toy("c")}, {toy("c")}}}), 0), "whole");
  EXPECT_EQ(on_release(plan_of({{"S", "", {toy("c")}, {}}, {"T", "", {}, {toy("c")}}}), 0), "whole");
  EXPECT_EQ(on_release(plan_of({{"P", "", {}, {toy("c")}}, {"S", "", {toy("c")}, {}}}), 1), "whole");
  EXPECT_EQ(on_release(plan_of({{"P", "", {}, {toy("c")}}, {"Q", "", {}, {}}, {"S", "", {toy("c")}, {}}}), 2), "held");
  EXPECT_EQ(on_release(plan_of({{"S", "", {toy("m")}, {}}}), 0, "c"), "whole");
}

// `colonflat run --to segment` (segment the last stage: its mask read by no later stage) writes
// lumen_mask.nrrd; it failed with "bad any_cast" when the mask was held as its stand-in first.
TEST(ArtifactParking, LastStagesOutputIsWrittenWhole) {
  if (!find_stage("segment")) GTEST_SKIP() << "this build has no segment stage";
  testing::TempDir dir;
  auto ph = testing::run_colonflat({"phantom", "--size", "small", "--seed", "3", "-o", dir.str("ph"), "-q"});
  ASSERT_EQ(ph.code, 0) << ph.err;
  auto run = testing::run_colonflat({"run", dir.str("ph/ct.nrrd"), "--to", "segment", "-o", dir.str("out"), "-q"});
  ASSERT_EQ(run.code, 0) << run.err;
  EXPECT_TRUE(fs::exists(dir / "out" / "lumen_mask.nrrd"));
}

// The CT is parked during segment (once its crop is copied; reconstruct takes the 16 bits), the
// mask after reconstruct (the last stage that reads it), the surfaces after denoise (flatten and
// render take triangle lists), the
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
  std::map<std::string, std::set<std::string>> held;  // stage -> artifacts parked after it ("during S": while it ran)
  for (const auto& h : report["held_compact"])
    held[h.contains("during_stage") ? "during " + h["during_stage"].get<std::string>() : h["after_stage"].get<std::string>()]
        .insert(h["artifact"].get<std::string>());
  EXPECT_EQ(held, (std::map<std::string, std::set<std::string>>{{"during segment", {"ct"}},
                                                                 {"reconstruct", {"mask"}},
                                                                 {"denoise", {"surface", "denoised"}}}));
  // denoised.vtp, written from its triangle list, and flat.vtp, mapped from it, are the files of
  // `colonflat denoise` and `colonflat flatten` on the run's surface.vtp.
  for (auto [stage, in, out] : {std::array<std::string, 3>{"denoise", "surface.vtp", "denoised.vtp"},
                                std::array<std::string, 3>{"flatten", "denoised.vtp", "flat.vtp"}}) {
    auto alone = testing::run_colonflat({stage, dir.str("out/" + in), "-o", dir.str("alone_" + out), "-q"});
    ASSERT_EQ(alone.code, 0) << alone.err;
    EXPECT_EQ(testing::slurp(dir / ("alone_" + out)), testing::slurp(dir / "out" / out)) << out;
  }
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
