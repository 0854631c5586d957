// ct_views: the lumen's LPS box, the CT plane stacks drawn ahead (in memory) and written later,
// and the report writing those it was given only when they are of its own box.
#include <gtest/gtest.h>

#include <cmath>
#include <tuple>

#include "colonflat/core/atomic_file.h"
#include "colonflat/report/ct_views.h"
#include "colonflat/report/report.h"
#include "colonflat/report/report_data.h"
#include "colonflat/report/run_data.h"
#include "colonflat/testing/files.h"
#include "colonflat/testing/temp_dir.h"
#include "synthetic_run.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

// A mask on an oblique grid (axes turned by 90 degrees about S, anisotropic voxels): the box is
// that of the two lumen voxels' index box mapped to LPS, worked out by hand; an empty mask has none.
TEST(ReportCt, MaskBoxIsTheLumenVoxelsBoxInLps) {
  auto m = MaskImage::New();
  MaskImage::SizeType size{{10, 12, 8}};
  m->SetRegions(size);
  const double sp[3] = {0.5, 0.75, 2.0}, org[3] = {10, -20, 30};
  m->SetSpacing(sp);
  m->SetOrigin(org);
  MaskImage::DirectionType d;
  d.Fill(0);
  d[0][1] = -1, d[1][0] = 1, d[2][2] = 1;  // i -> +P, j -> -L, k -> +S
  m->SetDirection(d);
  m->Allocate(true);
  std::array<double, 3> lo, hi;
  EXPECT_FALSE(mask_box_lps(*m, lo, hi));
  m->SetPixel({{2, 3, 1}}, 1);
  m->SetPixel({{6, 9, 5}}, 1);
  ASSERT_TRUE(mask_box_lps(*m, lo, hi));
  // L = 10 - 0.75 j, P = -20 + 0.5 i, S = 30 + 2 k over i in [2, 6], j in [3, 9], k in [1, 5]
  const std::array<double, 3> want_lo{10 - 0.75 * 9, -20 + 0.5 * 2, 30 + 2.0 * 1}, want_hi{10 - 0.75 * 3, -20 + 0.5 * 6, 30 + 2.0 * 5};
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(lo[a], want_lo[a], 1e-9) << a;
    EXPECT_NEAR(hi[a], want_hi[a], 1e-9) << a;
  }
}

// Stacks drawn in memory and written later are the files and JSON write_slice_stack writes at once.
TEST(ReportCt, PlanesDrawnAheadWriteTheSameFilesAndJson) {
  testing::TempDir tmp;
  const std::array<double, 3> lo{-20, -15, -10}, hi{20, 15, 12};
  const auto ct = testing::ball_ct(lo, hi, {3, -2, 1});
  SliceStackOptions so;
  so.step_mm = 4;
  so.margin_mm = 5;
  const DrawnPlaneStacks drawn = draw_plane_stacks(ct.GetPointer(), lo, hi, so);
  ASSERT_EQ(drawn.planes.size(), 3u);
  fs::create_directories(tmp / "ahead");
  fs::create_directories(tmp / "now");
  int i = 0;
  for (Plane p : {Plane::axial, Plane::coronal, Plane::sagittal}) {
    const nlohmann::json ahead = write_drawn_stack(drawn.planes[std::size_t(i++)], tmp / "ahead", "f/");
    const nlohmann::json now = write_slice_stack(ct.GetPointer(), p, lo, hi, so, tmp / "now", "f/");
    EXPECT_EQ(ahead, now) << plane_name(p);
    ASSERT_GT(now["files"].size(), 2u);
    for (const auto& f : now["files"]) {
      const std::string name = f.get<std::string>().substr(2);
      EXPECT_EQ(testing::slurp(tmp / "ahead" / name), testing::slurp(tmp / "now" / name)) << name;
    }
  }
}

// The CT in 16 bits (`colonflat run` holds it so from segment's crop on) draws the stacks of the
// float CT it holds, byte for byte; with 100.5 HU added everywhere (no 16-bit copy then) the float
// CT draws other pixels, so the comparison sees the HU.
TEST(ReportCt, PlanesOfTheCtInSixteenBitsAreThoseOfTheFloatCt) {
  const std::array<double, 3> lo{-20, -15, -10}, hi{20, 15, 12};
  const auto ct = testing::ball_ct(lo, hi, {3, -2, 1});
  float* hu = ct->GetBufferPointer();
  for (std::size_t q = 0, n = ct->GetLargestPossibleRegion().GetNumberOfPixels(); q < n; ++q) hu[q] = std::round(hu[q]);
  const CompactCtImage::Pointer ct16 = compact_ct(*ct);
  ASSERT_TRUE(ct16);
  SliceStackOptions so;
  so.step_mm = 4;
  so.margin_mm = 5;
  const DrawnPlaneStacks a = draw_plane_stacks(ct.GetPointer(), lo, hi, so);
  const DrawnPlaneStacks b = draw_plane_stacks(ct16.GetPointer(), lo, hi, so);
  ASSERT_EQ(a.planes.size(), 3u);
  ASSERT_EQ(b.planes.size(), 3u);
  std::size_t images = 0;
  for (std::size_t p = 0; p < 3; ++p) {
    EXPECT_EQ(a.planes[p].json, b.planes[p].json) << p;
    EXPECT_EQ(a.planes[p].pngs, b.planes[p].pngs) << p;
    images += a.planes[p].pngs.size();
  }
  EXPECT_GT(images, 6u);
  for (std::size_t q = 0, n = ct->GetLargestPossibleRegion().GetNumberOfPixels(); q < n; ++q) hu[q] += 100.5f;
  const DrawnPlaneStacks c = draw_plane_stacks(ct.GetPointer(), lo, hi, so);
  bool differs = false;
  for (std::size_t p = 0; p < 3; ++p) differs = differs || c.planes[p].pngs != b.planes[p].pngs;
  EXPECT_TRUE(differs);
}

// run_from_artifacts shares the CT as the run holds it: in 16 bits it stays so (the same image in
// the bag and in the RunData, no float copy), and a finding's CT views drawn from it are the float
// CT's, byte for byte.
TEST(ReportCt, RunDataKeepsTheCtInSixteenBitsAndDrawsTheSameViews) {
  testing::TempDir tmp;
  const std::array<double, 3> lo{-20, -15, -10}, hi{20, 15, 12};
  const auto ct = testing::ball_ct(lo, hi, {3, -2, 1});
  const CompactCtImage::Pointer ct16 = compact_ct(*ct);
  ASSERT_TRUE(ct16);
  ArtifactBag held, whole;
  held.put("ct", ct16);
  whole.put("ct", ct);
  const RunData a = run_from_artifacts(held, tmp / "a", nlohmann::json::object(), "ct.nrrd");
  const RunData b = run_from_artifacts(whole, tmp / "b", nlohmann::json::object(), "ct.nrrd");
  EXPECT_FALSE(a.ct);
  EXPECT_EQ(a.ct16.GetPointer(), ct16.GetPointer());
  EXPECT_EQ(std::any_cast<CompactCtImage::Pointer>(held.raw("ct")).GetPointer(), ct16.GetPointer());
  EXPECT_EQ(b.ct.GetPointer(), ct.GetPointer());
  EXPECT_TRUE(has_ct(a) && has_ct(b));
  ReportFinding f;
  f.key = "P1", f.id = 1, f.lps_mm = {3, -2, 1}, f.size_mm = 3;
  nlohmann::json ja, jb;
  for (auto [run, dir, j] : {std::tuple{&a, tmp / "a_files", &ja}, std::tuple{&b, tmp / "b_files", &jb}}) {
    fs::create_directories(dir);
    EXPECT_EQ(write_finding_images(*run, f, ReportOptions{}, dir, nullptr, nullptr, *j), 6);
  }
  EXPECT_EQ(ja, jb);
  for (const auto& e : fs::directory_iterator(tmp / "a_files"))
    EXPECT_EQ(testing::slurp(e.path()), testing::slurp(tmp / "b_files" / e.path().filename())) << e.path().filename();
}

// The report writes the planes it is given when they are of its box (its lumen's, here every
// voxel of the CT) and options, and draws its own when their box differs by 1 mm.
TEST(ReportCt, ReportWritesPlanesDrawnAheadOnlyForItsOwnBox) {
  testing::TempDir tmp;
  testing::make_synthetic_run(tmp / "run");
  RunData run = load_run(tmp / "run");
  ASSERT_TRUE(run.ct);
  auto lumen = MaskImage::New();
  lumen->CopyInformation(run.ct);
  lumen->SetRegions(run.ct->GetLargestPossibleRegion());
  lumen->Allocate();
  lumen->FillBuffer(1);
  run.lumen = lumen;
  std::array<double, 3> lo, hi;
  ASSERT_TRUE(mask_box_lps(*lumen, lo, hi));
  const ReportOptions opts;
  SliceStackOptions so;
  so.step_mm = opts.stack_step_mm;
  so.pixel_mm = opts.stack_pixel_mm;
  const std::string sentinel = "not a png";
  for (const double shift : {0.0, 1.0}) {
    std::array<double, 3> box_hi = hi;
    box_hi[2] += shift;
    DrawnPlaneStacks drawn = draw_plane_stacks(run.ct.GetPointer(), lo, box_hi, so);
    for (auto& stack : drawn.planes)
      for (auto& png : stack.pngs) png = sentinel;  // marks what was written from `drawn`
    OutputTransaction tx;
    const ReportResult r = build_review_report(run, opts, tx, nullptr, nullptr, &drawn);
    tx.commit();
    const std::string axial0 = testing::slurp(tmp / "run" / "report_files" / "axial_0.png");
    if (shift == 0.0) EXPECT_EQ(axial0, sentinel);
    else EXPECT_EQ(axial0.substr(1, 3), "PNG") << "drawn for another box, yet written";
    bool said = false;
    for (const auto& [phase, s] : r.phases) said = said || phase.find("planes") != std::string::npos &&
                                                          phase.find("drawn beside the stages") != std::string::npos;
    EXPECT_EQ(said, shift == 0.0);
  }
}

}  // namespace
}  // namespace cf
