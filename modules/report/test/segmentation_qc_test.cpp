// The report's Segmentation section on a small run folder built here: a CT with a gas-filled colon
// (the run's lumen) and bodies of tagged fluid that segment rejected (run_report.json decisions).
// The section outlines them in its montages, tags each with its number (tags never overlap, keep
// off the lumen's outline), lists them in the legend with reason, volume and slices, and Chromium
// renders it.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <sstream>
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

const char* const kCrowdReasons[3] = {"reaches beyond the colon's region (bone, vessel, bladder)",
                                      "touches the colon's side, not an end", "lies beside a colon segment, not at its end"};

// The crowd: 18 tagged-fluid balls of radius 12 mm at x in {5, 32}, y, z in {-28, 0, 28}
// (2-4 mm of tissue between neighbours), ball i rejected for kCrowdReasons[i % 3].
std::vector<std::array<double, 3>> crowd_centres() {
  std::vector<std::array<double, 3>> c;
  for (double x : {5.0, 32.0})
    for (double y : {-28.0, 0.0, 28.0})
      for (double z : {-28.0, 0.0, 28.0}) c.push_back({x, y, z});
  return c;
}

// CT 80 x 70 x 60 voxels of 1.5 x 1.5 x 2 mm, soft tissue 40 HU; a gas tube (radius 12 mm, along
// z at x = -25) is the lumen; a tagged-fluid ellipsoid (600 HU, radii 14 x 11 x 18 mm at (25, 8, 0),
// 11.6 mL) and a 1.6 mL gas ball (too small to draw) lie outside it. With `crowd`, the ellipsoid
// and the gas ball are replaced by the 18 crowd balls (each about 7 mL), all rejected.
void make_run(const fs::path& dir, double* fluid_ml, bool crowd = false) {
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
  const auto centres = crowd_centres();
  std::vector<std::size_t> ball_voxels(centres.size(), 0);
  for (int k = 0; k < 60; ++k)
    for (int j = 0; j < 70; ++j)
      for (int i = 0; i < 80; ++i) {
        const double x = org[0] + i * sp[0], y = org[1] + j * sp[1], z = org[2] + k * sp[2];
        const bool tube = std::hypot(x + 25, y) < 12;
        bool blob = !crowd && std::pow((x - 25) / 14, 2) + std::pow((y - 8) / 11, 2) + std::pow(z / 18, 2) < 1;
        const bool ball = !crowd && std::hypot(x - 25, y + 30, z - 30) < 7.3;
        for (std::size_t b = 0; crowd && b < centres.size(); ++b)
          if (std::hypot(x - centres[b][0], y - centres[b][1], z - centres[b][2]) < 12) blob = true, ++ball_voxels[b];
        ct->SetPixel({{i, j, k}}, tube || ball ? -1000.f : blob ? 600.f : 40.f);
        mask->SetPixel({{i, j, k}}, tube ? 1 : 0);
        fluid += blob;
      }
  *fluid_ml = fluid * sp[0] * sp[1] * sp[2] / 1000.0;
  write_ct_volume(ct, dir / "ct.nrrd");
  write_mask(mask, dir / "lumen_mask.nrrd");
  nlohmann::json decisions = {
      {{"what", "segment"}, {"volume_ml", 54.3}, {"position_lps_mm", {-25, 0, 0}}, {"decision", "kept"}, {"reason", "colon segment (54.3 mL gas)"}}};
  if (!crowd) {
    decisions.push_back({{"what", "fluid body"}, {"volume_ml", *fluid_ml}, {"position_lps_mm", {24, 9, 3}}, {"decision", "rejected"}, {"reason", kReason}});
    decisions.push_back({{"what", "gas body"}, {"volume_ml", 1.6}, {"position_lps_mm", {25, -30, 30}}, {"decision", "rejected"},
                         {"reason", "less gas than --min-segment-volume"}});
  }
  for (std::size_t b = 0; crowd && b < centres.size(); ++b)
    decisions.push_back({{"what", "fluid body"}, {"volume_ml", ball_voxels[b] * sp[0] * sp[1] * sp[2] / 1000.0},
                         {"position_lps_mm", centres[b]}, {"decision", "rejected"}, {"reason", kCrowdReasons[b % 3]}});
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
      if (!im["tags"].empty()) {
        ++labelled;
        EXPECT_EQ(im["tags"][0]["id"], 1);
        EXPECT_TRUE(im["tags"][0]["placed"].get<bool>());
        EXPECT_GT(r, 10) << im["file"];
      } else {
        EXPECT_EQ(r, 0) << im["file"];
      }
    }
    EXPECT_GE(labelled, 1) << plane << ": no slice through the rejected body";
    EXPECT_GT(green, 50) << plane;
  }
  EXPECT_GE(b["seen"].size(), 3u);  // one slice per plane at least
}

// Pixels of a montage PNG inside a tag's box that are the lumen outline's green.
int green_under(const fs::path& png, const nlohmann::json& t) {
  const ImagePtr im = read_png(png);
  int d[3];
  im->GetDimensions(d);
  int n = 0;
  for (int row = t["y"].get<int>(); row < t["y"].get<int>() + t["h"].get<int>(); ++row)
    for (int x = t["x"].get<int>(); x < t["x"].get<int>() + t["w"].get<int>(); ++x) {
      const auto* p = static_cast<unsigned char*>(im->GetScalarPointer(x, d[1] - 1 - row, 0));  // PNG rows from the bottom in VTK
      n += p[0] == 40 && p[1] == 230 && p[2] == 90;
    }
  return n;
}

// 18 rejected bodies of 3 reasons crowded beside the colon: on every montage each body seen has
// one placed tag, inside the image, overlapping no other tag and covering no lumen-outline pixel
// of the PNG; every body is in the legend data with its reason, its reason's colour (3 colours)
// and the slices that show it.
TEST(ReportSegmentation, CrowdedBodiesGetDisjointTagsAndALegend) {
  testing::TempDir tmp;
  double fluid_ml = 0;
  make_run(tmp / "run", &fluid_ml, true);
  write_review_report(tmp / "run", no_endoluminal());
  const nlohmann::json S = report_page_data(tmp / "run" / "report.html")["segmentation"];
  ASSERT_TRUE(S.contains("planes")) << S.dump();
  ASSERT_EQ(S["bodies"].size(), 18u);
  ASSERT_EQ(S["reasons"].size(), 3u);
  std::vector<int> tags_of(19, 0);
  int most = 0;
  for (const char* plane : {"coronal", "axial", "sagittal"})
    for (const auto& im : S["planes"][plane]) {
      const auto& tags = im["tags"];
      most = std::max(most, int(tags.size()));
      for (std::size_t i = 0; i < tags.size(); ++i) {
        const auto& t = tags[i];
        ASSERT_TRUE(t["placed"].get<bool>()) << im["file"] << " tag " << t["id"];
        ++tags_of[t["id"].get<std::size_t>()];
        EXPECT_TRUE(t["x"] >= 0 && t["y"] >= 0 && t["x"].get<int>() + t["w"].get<int>() <= im["w"].get<int>() &&
                    t["y"].get<int>() + t["h"].get<int>() <= im["h"].get<int>());
        EXPECT_EQ(green_under(tmp / "run" / im["file"].get<std::string>(), t), 0) << im["file"] << " tag " << t["id"];
        for (std::size_t j = 0; j < i; ++j) {
          const auto& u = tags[j];
          const bool apart = t["x"].get<int>() + t["w"].get<int>() <= u["x"].get<int>() || u["x"].get<int>() + u["w"].get<int>() <= t["x"].get<int>() ||
                             t["y"].get<int>() + t["h"].get<int>() <= u["y"].get<int>() || u["y"].get<int>() + u["h"].get<int>() <= t["y"].get<int>();
          EXPECT_TRUE(apart) << im["file"] << ": tags " << t["id"] << " and " << u["id"] << " overlap";
        }
      }
    }
  EXPECT_GE(most, 6) << "no crowded slice";
  for (const auto& b : S["bodies"]) {
    const int id = b["id"].get<int>();
    EXPECT_EQ(b["reason"], kCrowdReasons[(id - 1) % 3]) << id;
    EXPECT_EQ(b["colour"], S["reasons"][b["reason_index"].get<std::size_t>()]["colour"]) << id;
    EXPECT_EQ(int(b["seen"].size()), tags_of[std::size_t(id)]) << id;
    EXPECT_GE(b["volume_ml"].get<double>(), 5.0);
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

// The CT in 16 bits (`colonflat run` holds it so from segment's crop on) gives the drawing of the
// float CT it holds: the same section and every montage's pixels.
TEST(ReportSegmentation, DrawingFromTheCtInSixteenBitsIsTheSame) {
  testing::TempDir tmp;
  double fluid_ml = 0;
  make_run(tmp / "run", &fluid_ml);
  const auto ct = read_ct_volume(tmp / "run" / "ct.nrrd");
  const auto ct16 = compact_ct(*ct);  // the phantom's HU are whole numbers
  ASSERT_TRUE(ct16);
  const auto mask = read_mask(tmp / "run" / "lumen_mask.nrrd");
  const nlohmann::json result = read_json_file(tmp / "run" / "run_report.json")["stages"][0]["result"];
  const SegmentationQcDrawing a = draw_segmentation_qc(ct.GetPointer(), mask.GetPointer(), result);
  const SegmentationQcDrawing b = draw_segmentation_qc(ct16.GetPointer(), mask.GetPointer(), result);
  ASSERT_GE(a.montages.size(), 12u);
  EXPECT_GE(a.section["bodies"].size(), 1u);
  EXPECT_EQ(a.section, b.section);
  ASSERT_EQ(a.montages.size(), b.montages.size());
  for (std::size_t i = 0; i < a.montages.size(); ++i) EXPECT_EQ(a.montages[i].rgb, b.montages[i].rgb) << a.montages[i].name;
}

bool have_chromium() { return std::system("command -v chromium > /dev/null 2>&1") == 0; }

// Headless Chromium builds the section of the crowded run: >= 12 montage images, one numbered
// tag element per placed tag (at its box, in % of the image), every dropped body's legend row
// with its number, reason and volume, the reason key (3 reasons), the kept segment's row.
TEST(ReportSegmentationBrowser, ChromiumShowsTagsAndLegendOfEveryDroppedBody) {
  if (!have_chromium()) GTEST_SKIP() << "chromium is not installed (scripts/install-deps.sh installs it)";
  testing::TempDir tmp;
  double fluid_ml = 0;
  make_run(tmp / "run", &fluid_ml, true);
  write_review_report(tmp / "run", no_endoluminal());
  const nlohmann::json S = report_page_data(tmp / "run" / "report.html")["segmentation"];
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
  // the tags in the DOM: number and box corner (% of the image)
  std::vector<std::array<double, 3>> dom_tags;
  const std::regex tag_re("class=\"seg-tag\" data-body=\"([0-9]+)\"[^>]*style=\"left: ([0-9.]+)%; top: ([0-9.]+)%");
  for (auto it = std::sregex_iterator(dom.begin(), dom.end(), tag_re); it != std::sregex_iterator(); ++it)
    dom_tags.push_back({std::stod((*it)[1]), std::stod((*it)[2]), std::stod((*it)[3])});
  int placed = 0;
  for (const char* plane : {"coronal", "axial", "sagittal"})
    for (const auto& im : S["planes"][plane])
      for (const auto& t : im["tags"]) {
        placed += t["placed"].get<bool>();
        const double left = 100.0 * t["x"].get<int>() / im["w"].get<int>(), top = 100.0 * t["y"].get<int>() / im["h"].get<int>();
        EXPECT_TRUE(std::any_of(dom_tags.begin(), dom_tags.end(), [&](const std::array<double, 3>& d) {
          return d[0] == t["id"].get<int>() && std::abs(d[1] - left) < 0.01 && std::abs(d[2] - top) < 0.01;
        })) << "tag " << t["id"] << " not at " << left << "%, " << top << "%";
      }
  EXPECT_EQ(int(dom_tags.size()), placed);
  EXPECT_EQ(count("class=\"seg-tag\""), placed);
  for (const auto& b : S["bodies"]) {
    const std::string id = std::to_string(b["id"].get<int>());
    std::ostringstream row;
    row << "class=\"seg-rejected\" data-body=\"" << id << "\"><td><span class=\"seg-swatch\"[^>]*>" << id << "</span></td><td>"
        << std::regex_replace(b["reason"].get<std::string>(), std::regex("[()]"), "\\$&") << "</td><td>"
        << std::fixed << std::setprecision(1) << b["volume_ml"].get<double>() << " mL</td>";
    EXPECT_EQ(count(row.str()), 1) << row.str();
  }
  EXPECT_EQ(count("class=\"seg-reason\""), 3);
  EXPECT_EQ(count("class=\"seg-kept\""), 1);
  if (const char* keep = std::getenv("COLONFLAT_KEEP_SEGMENTATION")) fs::copy(tmp / "run", keep, fs::copy_options::recursive | fs::copy_options::overwrite_existing);
}

}  // namespace
}  // namespace cf
