// The report's Segmentation section on a small run folder built here: a CT with a gas-filled colon
// (the run's lumen) and a body of tagged fluid that segment rejected (run_report.json decision).
// The section outlines both in its montages, labels the body with its reason and volume, and
// Chromium renders it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <regex>

#include <vtkImageData.h>

#include "colonflat/core/stage.h"
#include "colonflat/core/threads.h"
#include "colonflat/render/artifacts.h"
#include "colonflat/report/report.h"
#include "colonflat/report/segmentation_qc.h"
#include "colonflat/testing/temp_dir.h"
#include "colonflat/volume/volume_io.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

constexpr const char* kReason = "lies beside a colon segment, not at its end";

// CT 80 x 70 x 60 voxels of 1.5 x 1.5 x 2 mm, soft tissue 40 HU; a gas tube (radius 12 mm, along
// z at x = -25) is the lumen; a tagged-fluid ellipsoid (600 HU, radii 14 x 11 x 18 mm at (25, 8, 0),
// 11.6 mL) and a 1.6 mL gas ball (too small to draw) lie outside it.
void make_run(const fs::path& dir, double* fluid_ml) {
  fs::create_directories(dir);
  auto ct = CtImage::New();
  auto mask = MaskImage::New();
  const double sp[3] = {1.5, 1.5, 2.0}, org[3] = {-60, -52, -60};
  for (itk::ImageBase<3>* im : {static_cast<itk::ImageBase<3>*>(ct.GetPointer()), static_cast<itk::ImageBase<3>*>(mask.GetPointer())}) {
    im->SetRegions(itk::ImageRegion<3>(itk::Size<3>{{80, 70, 60}}));
    im->SetSpacing(sp);
    im->SetOrigin(org);
  }
  ct->Allocate();
  mask->Allocate();
  std::size_t fluid = 0;
  for (int k = 0; k < 60; ++k)
    for (int j = 0; j < 70; ++j)
      for (int i = 0; i < 80; ++i) {
        const double x = org[0] + i * sp[0], y = org[1] + j * sp[1], z = org[2] + k * sp[2];
        const bool tube = std::hypot(x + 25, y) < 12;
        const bool blob = std::pow((x - 25) / 14, 2) + std::pow((y - 8) / 11, 2) + std::pow(z / 18, 2) < 1;
        const bool ball = std::hypot(x - 25, y + 30, z - 30) < 7.3;
        ct->SetPixel({{i, j, k}}, tube || ball ? -1000.f : blob ? 600.f : 40.f);
        mask->SetPixel({{i, j, k}}, tube ? 1 : 0);
        fluid += blob;
      }
  *fluid_ml = fluid * sp[0] * sp[1] * sp[2] / 1000.0;
  write_ct_volume(ct, dir / "ct.nrrd");
  write_mask(mask, dir / "lumen_mask.nrrd");
  const nlohmann::json decisions = {
      {{"what", "segment"}, {"volume_ml", 54.3}, {"position_lps_mm", {-25, 0, 0}}, {"decision", "kept"}, {"reason", "colon segment (54.3 mL gas)"}},
      {{"what", "fluid body"}, {"volume_ml", *fluid_ml}, {"position_lps_mm", {24, 9, 3}}, {"decision", "rejected"}, {"reason", kReason}},
      {{"what", "gas body"}, {"volume_ml", 1.6}, {"position_lps_mm", {25, -30, 30}}, {"decision", "rejected"}, {"reason", "less gas than --min-segment-volume"}}};
  const nlohmann::json result = {{"segments", 1}, {"segment_volumes_ml", {54.3}}, {"decisions", decisions},
                                 {"class_means_hu", {{"air", -1000}, {"tissue", 40}, {"fluid", 600}}}};
  std::ofstream(dir / "run_report.json") << nlohmann::json{{"version", "test"}, {"input", (dir / "ct.nrrd").string()},
                                                           {"stages", {{{"stage", "segment"}, {"time_s", 1.0}, {"result", result}}}}}
                                                .dump(2);
}

ReportOptions no_endoluminal() {
  ReportOptions o;
  o.endoluminal = false;
  return o;
}

// Red (body outline) and green (lumen outline) pixels of a montage PNG.
std::pair<int, int> outline_pixels(const fs::path& png) {
  const ImagePtr im = read_png(png);
  int d[3];
  im->GetDimensions(d);
  int red = 0, green = 0;
  for (int y = 0; y < d[1]; ++y)
    for (int x = 0; x < d[0]; ++x) {
      const auto* p = static_cast<unsigned char*>(im->GetScalarPointer(x, y, 0));
      red += p[0] == 255 && p[1] == 50 && p[2] == 30;
      green += p[0] == 40 && p[1] == 230 && p[2] == 90;
    }
  return {red, green};
}

// The rejected fluid body is found from its decision (volume within 15 % of the truth), listed
// with its reason, labelled and outlined in red on slices through it; the lumen is outlined green
// on every plane's montage of at least 4 slices; the 1.6 mL body is counted, not drawn.
TEST(ReportSegmentation, DroppedBodyIsOutlinedLabelledAndListed) {
  testing::TempDir tmp;
  double fluid_ml = 0;
  make_run(tmp / "run", &fluid_ml);
  write_review_report(tmp / "run", no_endoluminal());
  const nlohmann::json S = report_page_data(tmp / "run" / "report.html")["segmentation"];
  ASSERT_TRUE(S.contains("planes")) << S.dump();
  ASSERT_EQ(S["bodies"].size(), 1u);
  const auto& b = S["bodies"][0];
  EXPECT_EQ(b["reason"], kReason);
  EXPECT_TRUE(b["outlined"].get<bool>());
  EXPECT_EQ(b["kind"], "tagged fluid");
  EXPECT_NEAR(b["measured_ml"].get<double>(), fluid_ml, 0.15 * fluid_ml);
  EXPECT_EQ(S["small_rejected"]["count"], 1);
  EXPECT_EQ(S["kept"].size(), 1u);
  for (const char* plane : {"coronal", "axial", "sagittal"}) {
    ASSERT_GE(S["planes"][plane].size(), 4u) << plane;
    int labelled = 0, green = 0;
    for (const auto& im : S["planes"][plane]) {
      const auto [r, g] = outline_pixels(tmp / "run" / im["file"].get<std::string>());
      green += g;
      if (!im["labels"].empty()) {
        ++labelled;
        EXPECT_EQ(im["labels"][0]["id"], 1);
        EXPECT_GT(r, 10) << im["file"];
      } else {
        EXPECT_EQ(r, 0) << im["file"];
      }
    }
    EXPECT_GE(labelled, 1) << plane << ": no slice through the rejected body";
    EXPECT_GT(green, 50) << plane;
  }
}

// The montages are drawn on the threads, each slice into its own slot: the section and every
// montage's pixels are the same for 1 and 2 threads.
TEST(ReportSegmentation, DrawingIsTheSameForOneAndTwoThreads) {
  testing::TempDir tmp;
  double fluid_ml = 0;
  make_run(tmp / "run", &fluid_ml);
  const auto ct = read_ct_volume(tmp / "run" / "ct.nrrd");
  const auto mask = read_mask(tmp / "run" / "lumen_mask.nrrd");
  const nlohmann::json result = read_json_file(tmp / "run" / "run_report.json")["stages"][0]["result"];
  set_thread_count(1);
  const SegmentationQcDrawing one = draw_segmentation_qc(ct.GetPointer(), mask.GetPointer(), result);
  set_thread_count(2);
  const SegmentationQcDrawing two = draw_segmentation_qc(ct.GetPointer(), mask.GetPointer(), result);
  set_thread_count(0);
  ASSERT_GE(one.montages.size(), 12u);
  EXPECT_EQ(one.section, two.section);
  ASSERT_EQ(one.montages.size(), two.montages.size());
  for (std::size_t i = 0; i < one.montages.size(); ++i) {
    EXPECT_EQ(one.montages[i].name, two.montages[i].name);
    EXPECT_EQ(one.montages[i].rgb, two.montages[i].rgb) << one.montages[i].name;
  }
}

bool have_chromium() { return std::system("command -v chromium > /dev/null 2>&1") == 0; }

// Headless Chromium builds the section: >= 12 montage images, the body's label with its reason and
// volume over the images, its row in the rejected table, the kept segment's row.
TEST(ReportSegmentationBrowser, ChromiumShowsDroppedBodyWithReason) {
  if (!have_chromium()) GTEST_SKIP() << "chromium is not installed (scripts/install-deps.sh installs it)";
  testing::TempDir tmp;
  double fluid_ml = 0;
  make_run(tmp / "run", &fluid_ml);
  write_review_report(tmp / "run", no_endoluminal());
  const std::string cmd = "timeout 180 chromium --headless --no-sandbox --disable-gpu --no-first-run --user-data-dir=" +
                          (tmp / "profile").string() + " --virtual-time-budget=5000 --dump-dom file://" +
                          fs::absolute(tmp / "run" / "report.html").string() + " > " + (tmp / "dom.html").string() + " 2> " +
                          (tmp / "log").string();
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  std::ifstream in(tmp / "dom.html");
  const std::string dom((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(dom.find("data-ready=\"1\""), std::string::npos);
  const auto count = [&](const std::string& re) {
    const std::regex r(re);
    return std::distance(std::sregex_iterator(dom.begin(), dom.end(), r), std::sregex_iterator());
  };
  EXPECT_GE(count("<img src=\"report_files/seg_(coronal|axial|sagittal)_[0-9]+\\.png\""), 12);
  std::ostringstream label;
  label << "R1 " << std::lround(fluid_ml) << " mL: " << kReason;
  EXPECT_GE(count("class=\"seg-label\" data-body=\"R1\"[^>]*>" + label.str() + "<"), 3) << dom.substr(0, 3000);
  EXPECT_EQ(count("class=\"seg-rejected\" data-body=\"R1\""), 1);
  EXPECT_EQ(count("class=\"seg-kept\""), 1);
}

}  // namespace
}  // namespace cf
