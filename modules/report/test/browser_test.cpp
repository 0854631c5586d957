// The report in a real browser: headless Chromium (Debian package `chromium`) loads report.html
// from disk, runs its script, and the DOM it dumps holds the candidate cards, the colon image, the
// CT views at the selected candidate; the screenshot is a non-blank page. Skipped only where
// chromium is not installed (CI installs it).
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>

#include <vtkImageData.h>

#include "colonflat/render/artifacts.h"
#include "colonflat/report/report.h"
#include "colonflat/testing/temp_dir.h"
#include "synthetic_run.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

bool have_chromium() { return std::system("command -v chromium > /dev/null 2>&1") == 0; }

std::string chromium(const fs::path& profile, const std::string& args) {
  return "timeout 180 chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run "
         "--disable-background-networking --disable-component-update --disable-sync --user-data-dir=" +
         profile.string() + " " + args;
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

int count(const std::string& text, const std::regex& re) {
  return int(std::distance(std::sregex_iterator(text.begin(), text.end(), re), std::sregex_iterator()));
}

// The page's script built one card per candidate and per known polyp (each with 3 CT planes in
// two windows, a colon crop and an endoluminal view), shows the colon image with a mark per
// finding, and the 3 CT planes at the top candidate; the screenshot is not blank.
TEST(ReportBrowser, HeadlessChromiumShowsCardsImageAndCtViews) {
  if (!have_chromium()) GTEST_SKIP() << "chromium is not installed (scripts/install-deps.sh installs it)";
  testing::TempDir tmp;
  const auto run = testing::make_synthetic_run(tmp / "run");
  const ReportResult rr = write_review_report(tmp / "run");
  ASSERT_EQ(rr.endoluminal_views, rr.candidates + rr.known_polyps) << "no display for the endoluminal views";
  const std::string url = "file://" + fs::absolute(tmp / "run" / "report.html").string();
  const int dump = std::system((chromium(tmp / "profile1", "--virtual-time-budget=5000 --dump-dom " + url) + " > " +
                                (tmp / "dom.html").string() + " 2> " + (tmp / "chromium.log").string()).c_str());
  ASSERT_EQ(dump, 0) << read_text(tmp / "chromium.log");
  const std::string dom = read_text(tmp / "dom.html");
  const int n_cand = int(run.candidates["candidates"].size());
  EXPECT_NE(dom.find("data-ready=\"1\""), std::string::npos) << "the page script did not finish";
  EXPECT_EQ(count(dom, std::regex("class=\"card candidate[^\"]*\"")), n_cand);
  EXPECT_EQ(count(dom, std::regex("class=\"card known[^\"]*\"")), run.known_polyps);
  EXPECT_EQ(count(dom, std::regex("class=\"tile ct-tile\"")), 3 * (n_cand + run.known_polyps));
  EXPECT_EQ(count(dom, std::regex("<img src=\"report_files/[A-Z0-9]+_endoluminal\\.png\"")), n_cand + run.known_polyps);
  EXPECT_NE(dom.find("id=\"colon-img\""), std::string::npos);
  EXPECT_NE(dom.find("src=\"colon.png\""), std::string::npos);
  EXPECT_EQ(count(dom, std::regex("class=\"mark (cand|known)\"")), n_cand + run.known_polyps);
  // the CT panel shows the three planes of the stacks at the top candidate
  EXPECT_EQ(count(dom, std::regex("class=\"ct-view\" data-plane=\"(axial|coronal|sagittal)\"")), 3);
  EXPECT_EQ(count(dom, std::regex("background-image: url\\(&quot;report_files/(axial|coronal|sagittal)_[0-9]+\\.png")), 3)
      << dom.substr(0, 2000);
  const int shot = std::system((chromium(tmp / "profile2", "--virtual-time-budget=5000 --window-size=1400,1800 "
                                "--hide-scrollbars --screenshot=" + (tmp / "shot.png").string() + " " + url) +
                                " > /dev/null 2>> " + (tmp / "chromium.log").string()).c_str());
  ASSERT_EQ(shot, 0) << read_text(tmp / "chromium.log");
  const ImagePtr png = read_png(tmp / "shot.png");
  int dims[3];
  png->GetDimensions(dims);
  EXPECT_EQ(dims[0], 1400);
  EXPECT_EQ(dims[1], 1800);
  double range[2];
  png->GetScalarRange(range);
  EXPECT_GT(range[1] - range[0], 100) << "blank screenshot";
  if (const char* keep = std::getenv("COLONFLAT_KEEP_SCREENSHOT")) fs::copy_file(tmp / "shot.png", keep, fs::copy_options::overwrite_existing);
}

}  // namespace
}  // namespace cf
