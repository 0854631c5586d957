// The supine-prone review page (issue 17, item 3): `colonflat run SUP --prone PRO -o OUT` (from
// memory) and `colonflat register SUP_RUN PRO_RUN -o DIR` (from files) write report.html beside
// the registration: per candidate pair both scans' views, per one-scan-only candidate the other
// scan's views at the registered position of its point. Small phantom pair, seed 1: one pair and
// one supine-only candidate.
#include <gtest/gtest.h>

#include <vtkImageData.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <regex>

#include <nlohmann/json.hpp>

#include "colonflat/core/stage.h"
#include "colonflat/pipeline/registry.h"
#include "colonflat/register/register.h"
#include "colonflat/register/scan.h"
#include "colonflat/render/artifacts.h"
#include "colonflat/report/report.h"
#include "colonflat/testing/command.h"
#include "colonflat/testing/temp_dir.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// The side (px) of a PNG under `dir`, 0 when it is missing or does not decode.
int png_side(const fs::path& dir, const nlohmann::json& rel) {
  if (!rel.is_string() || !fs::exists(dir / rel.get<std::string>())) return 0;
  int dims[3];
  read_png(dir / rel.get<std::string>())->GetDimensions(dims);
  return dims[0] == dims[1] ? dims[0] : 0;
}

// A card's views: three CT planes in two windows, the colon-map crop and the endoluminal view,
// each a decodable square PNG of the report's default size, named after the scan and the key.
void expect_views(const fs::path& dir, const nlohmann::json& f, const std::string& file_key) {
  SCOPED_TRACE(file_key);
  for (const char* plane : {"axial", "coronal", "sagittal"})
    for (const char* window : {"lung", "soft"}) {
      const nlohmann::json& file = f["ct"][plane][window];
      EXPECT_EQ(png_side(dir, file), 160) << plane << " " << window;
      EXPECT_EQ(file.get<std::string>(), "report_files/" + file_key + "_" + plane + "_" + window + ".png");
    }
  EXPECT_EQ(png_side(dir, f["flat_thumbnail"]), 200);
  EXPECT_EQ(png_side(dir, f["endoluminal"]), 256) << "no display for the endoluminal view?";
}

struct Pair {
  ColonScan supine, prone;
};

// Candidate `id`'s LPS position in a run folder's candidates.json.
Eigen::Vector3d candidate_lps(const ColonScan& scan, int id) {
  for (const ScanCandidate& c : scan.candidates)
    if (c.id == id) return c.lps;
  ADD_FAILURE() << "no candidate " << id << " in " << scan.name;
  return Eigen::Vector3d::Zero();
}

// Every pair and single of registration.json is on the page in `dir`, with the views of both
// scans (pairs) or the other scan's views at register's mapping of the candidate (singles).
void expect_review(const fs::path& dir, const ColonRegistration& reg) {
  const nlohmann::json page = report_page_data(dir / "report.html");
  ASSERT_TRUE(page.is_object()) << "no window.REPORT in " << dir / "report.html";
  const nlohmann::json cands = read_json_file(dir / "registration.json")["candidates"];
  ASSERT_EQ(page["pairs"].size(), cands["pairs"].size());
  for (std::size_t i = 0; i < cands["pairs"].size(); ++i) {
    const auto &p = page["pairs"][i], &c = cands["pairs"][i];
    const std::string s = "P" + std::to_string(c["supine_id"].get<int>()), r = "P" + std::to_string(c["prone_id"].get<int>());
    EXPECT_EQ(p["supine"]["key"], s);
    EXPECT_EQ(p["prone"]["key"], r);
    EXPECT_NEAR(p["along_mm"].get<double>(), c["along_mm"].get<double>(), 0.06);
    expect_views(dir, p["supine"], "supine_" + s);
    expect_views(dir, p["prone"], "prone_" + r);
  }
  ASSERT_EQ(page["singles"].size(), cands["supine_only"].size() + cands["prone_only"].size());
  for (const auto& single : page["singles"]) {
    const bool supine = single["scan"] == "supine";
    const std::string key = single["finding"]["key"], other = supine ? "prone" : "supine";
    expect_views(dir, single["finding"], single["scan"].get<std::string>() + "_" + key);
    expect_views(dir, single["probe"], other + "_at_" + single["scan"].get<std::string>() + "_" + key);
    const Eigen::Vector3d p = candidate_lps(supine ? reg.supine() : reg.prone(), std::stoi(key.substr(1)));
    const Eigen::Vector3d want = reg.map_lps(p, supine ? Direction::kSupineToProne : Direction::kProneToSupine);
    const auto got = single["probe"]["lps_mm"].get<std::array<double, 3>>();
    EXPECT_LT((Eigen::Vector3d(got[0], got[1], got[2]) - want).norm(), 1.0) << key << ": " << want.transpose();
  }
}

int count(const std::string& text, const std::string& re) {
  const std::regex r(re);
  return int(std::distance(std::sregex_iterator(text.begin(), text.end(), r), std::sregex_iterator()));
}

// The page in headless Chromium: one row per pair and per single, two cards each (the single's
// second card the dashed "check here" card), three CT tiles per card, every image loaded from report_files/.
void expect_browser_page(const fs::path& dir, const fs::path& tmp, int pairs, int singles) {
  if (std::system("command -v chromium > /dev/null 2>&1") != 0) return;
  const std::string cmd = "timeout 180 chromium --headless --no-sandbox --disable-gpu --no-first-run "
                          "--disable-background-networking --user-data-dir=" + (tmp / "profile").string() +
                          " --virtual-time-budget=5000 --dump-dom file://" + fs::absolute(dir / "report.html").string() +
                          " > " + (tmp / "dom.html").string() + " 2> /dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  const std::string dom = read_text(tmp / "dom.html");
  EXPECT_NE(dom.find("data-ready=\"1\""), std::string::npos) << "the page script did not finish";
  EXPECT_EQ(count(dom, "class=\"pair\""), pairs);
  EXPECT_EQ(count(dom, "class=\"pair single\""), singles);
  EXPECT_EQ(count(dom, "class=\"card candidate probe\""), singles);
  EXPECT_EQ(count(dom, "not found in (prone|supine) - check here"), singles);
  EXPECT_EQ(count(dom, "class=\"tile ct-tile\""), 3 * 2 * (pairs + singles));
  EXPECT_EQ(count(dom, "<img src=\"report_files/[a-z_]+P[0-9]+_endoluminal\\.png\""), 2 * (pairs + singles));
  EXPECT_EQ(count(dom, "id=\"sbs-img\"[^>]*src=\"supine_prone.png\"|src=\"supine_prone.png\"[^>]*id=\"sbs-img\""), 1);
}

class TwoScanReview : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto tools = registered_module_tools();
    for (const char* tool : {"phantom", "register", "report"})
      if (std::none_of(tools.begin(), tools.end(), [&](const auto& t) { return t->name() == tool; }))
        GTEST_SKIP() << "this build lacks " << tool;
    for (const char* position : {"supine", "prone"}) {
      const auto p = testing::run_colonflat({"phantom", "-o", dir_.str(position), "--seed", "1", "--size", "small",
                                             "--position", position, "-q"});
      ASSERT_EQ(p.code, 0) << p.err;
    }
  }
  testing::CommandResult run_pair(const std::string& out) {
    return testing::run_colonflat({"run", dir_.str("supine/ct.nrrd"), "--prone", dir_.str("prone/ct.nrrd"), "-o",
                                   dir_.str(out), "--set", "render.snapshots=false", "-q"});
  }
  testing::TempDir dir_;
};

// From memory (`run --prone`) and from the run folders (`register`): each pair shows both scans'
// views with the right ids, the supine-only candidate shows the prone views at register's mapping
// of its point (within 1 mm), and a browser builds a row of two cards for each.
TEST_F(TwoScanReview, PairsShowBothScansAndSinglesTheOtherScanAtTheMappedPoint) {
  const auto r = run_pair("out");
  ASSERT_EQ(r.code, 0) << r.err;
  const ColonScan sup = read_run_dir(dir_ / "out" / "supine"), pro = read_run_dir(dir_ / "out" / "prone");
  ColonRegistration reg(sup, pro);
  reg.run();
  ASSERT_GE(reg.matching().pairs.size(), 1u) << "the seed-1 pair should have a candidate pair";
  ASSERT_GE(reg.matching().supine_only.size() + reg.matching().prone_only.size(), 1u);
  expect_review(dir_ / "out" / "registration", reg);
  const auto f = testing::run_colonflat({"register", dir_.str("out/supine"), dir_.str("out/prone"), "-o", dir_.str("files"), "-q"});
  ASSERT_EQ(f.code, 0) << f.err;
  expect_review(dir_ / "files", reg);
  const nlohmann::json page = report_page_data(dir_ / "files" / "report.html");
  EXPECT_TRUE(fs::exists(dir_ / "files" / page["scans"]["supine"]["report"].get<std::string>()));  // link to the run's page
  expect_browser_page(dir_ / "files", dir_.path(), int(reg.matching().pairs.size()),
                      int(reg.matching().supine_only.size() + reg.matching().prone_only.size()));
}

// A review that fails (injected after its images are written) fails the two-scan run with one
// error line, and neither scan's outputs nor the registration appear.
TEST_F(TwoScanReview, FailingReviewLeavesNoOutputOfEitherScan) {
  ::setenv("COLONFLAT_TEST_FAIL", "review", 1);
  const auto r = run_pair("out");
  ::unsetenv("COLONFLAT_TEST_FAIL");
  EXPECT_NE(r.code, 0);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("failure injected"), std::string::npos) << r.err;
  for (const char* f : {"supine/flat.vtp", "supine/report.html", "prone/candidates.json", "registration/report.html",
                        "registration/registration.json", "registration/report_files"})
    EXPECT_FALSE(fs::exists(dir_ / "out" / f)) << f;
}

}  // namespace
}  // namespace cf
