// DICOM results (issue 28 item 2): the lumen SEG, the candidates SR and the Secondary Capture lie
// in the source study, pass dciodvfy (dicom3tools) without errors, and pydicom reads back SEG frames
// equal to the mask and SR points equal to the candidates.
#include <gtest/gtest.h>
#include <vtkImageData.h>
#include <vtkSmartPointer.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>

#include "colonflat/core/error.h"
#include "colonflat/dicom/results.h"
#include "colonflat/testing/shell.h"
#include "colonflat/testing/temp_dir.h"
#include "colonflat/volume/volume_io.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

using testing::shell;

// dciodvfy's lines that report errors ("Error - ...").
std::string dciodvfy_errors(const fs::path& file) {
  const auto [code, out] = shell("dciodvfy " + file.string());
  std::istringstream in(out);
  std::string errors;
  for (std::string line; std::getline(in, line);)
    if (line.rfind("Error", 0) == 0) errors += line + "\n";
  return errors;
}

class DicomResults : public ::testing::Test {
 protected:
  void SetUp() override {
    // An 8 x 5 x 12 CT at 1.5 x 1.5 x 2.5 mm, off-centre origin, written as a DICOM series.
    ct_ = CtImage::New();
    ct_->SetRegions(CtImage::SizeType{{8, 5, 12}});
    CtImage::SpacingType sp;
    sp[0] = sp[1] = 1.5, sp[2] = 2.5;
    ct_->SetSpacing(sp);
    CtImage::PointType o;
    o[0] = -10, o[1] = 20.25, o[2] = -300;
    ct_->SetOrigin(o);
    ct_->Allocate();
    ct_->FillBuffer(40.f);
    DicomWriteOptions w;
    w.patient_id = "SEG-TEST";
    w.patient_position = "HFS";
    write_dicom_series(ct_.GetPointer(), dir_ / "ct", w);
    mask_ = MaskImage::New();
    mask_->CopyInformation(ct_);
    mask_->SetRegions(ct_->GetLargestPossibleRegion());
    mask_->Allocate();
    mask_->FillBuffer(0);
    for (int k = 3; k < 9; ++k)  // a lumen crossing 6 slices, its shape changing with k
      for (int j = 1; j < 4; ++j)
        for (int i = 1; i < 2 + k % 4; ++i) mask_->SetPixel({{i, j, k}}, 1);
  }
  testing::TempDir dir_;
  CtImage::Pointer ct_;
  MaskImage::Pointer mask_;
};

// The SEG names the source's patient, study and frame of reference, has a new series, one frame
// per slice holding lumen, and passes dciodvfy without errors.
TEST_F(DicomResults, InTheSourceStudyAndValid) {
  const SourceSeries src = read_source_series(dir_ / "ct");
  ASSERT_EQ(src.slices.size(), 12u);
  const fs::path seg = dir_ / "out" / "seg.dcm";
  write_lumen_seg(mask_.GetPointer(), src, seg);
  ASSERT_TRUE(fs::exists(seg));
  if (shell("command -v dciodvfy").first != 0) GTEST_SKIP() << "dciodvfy (dicom3tools) not installed";
  EXPECT_EQ(dciodvfy_errors(seg), "") << shell("dciodvfy " + seg.string()).second;
}

// pydicom reads back 6 frames, each on its source slice (same z, same referenced SOPInstanceUID)
// with exactly the mask's pixels; the header carries the source's UIDs.
TEST_F(DicomResults, PydicomReadsFramesEqualToTheMask) {
  const SourceSeries src = read_source_series(dir_ / "ct");
  const fs::path seg = dir_ / "seg.dcm";
  write_lumen_seg(mask_.GetPointer(), src, seg);
  const auto [code, out] = shell(std::string(COLONFLAT_PYDICOM_PYTHON) + " " + COLONFLAT_SOURCE_DIR +
                                 "/modules/dicom/test/read_seg.py " + seg.string());
  if (code != 0 && out.find("No module named") != std::string::npos) GTEST_SKIP() << "no pydicom: " << out;
  ASSERT_EQ(code, 0) << out;
  std::istringstream in(out);
  std::string sop_class, study, patient, frame, series;
  int frames = 0, rows = 0, cols = 0;
  in >> sop_class >> study >> patient >> frame >> series >> frames >> rows >> cols;
  EXPECT_EQ(sop_class, "1.2.840.10008.5.1.4.1.1.66.4");
  EXPECT_EQ(study, src.study_uid);
  EXPECT_EQ(patient, "SEG-TEST");
  EXPECT_EQ(frame, src.frame_of_reference_uid);
  EXPECT_NE(series, src.series_uid);
  ASSERT_EQ(frames, 6);
  EXPECT_EQ(rows, 5);
  EXPECT_EQ(cols, 8);
  std::map<int, int> seen;
  for (int f = 0; f < frames; ++f) {
    double z = 0;
    std::string source, bits;
    in >> z >> source >> bits;
    const int k = int(std::lround((z + 300) / 2.5));
    ASSERT_TRUE(k >= 0 && k < 12) << z;
    ++seen[k];
    const SourceSlice* s = src.slice_at(z);
    ASSERT_NE(s, nullptr);
    EXPECT_EQ(source, s->sop_instance_uid);
    std::string want;
    for (int j = 0; j < 5; ++j)
      for (int i = 0; i < 8; ++i) want += mask_->GetPixel({{i, j, k}}) ? '1' : '0';
    EXPECT_EQ(bits, want) << "slice " << k;
  }
  EXPECT_EQ(seen.size(), 6u);
  EXPECT_EQ(seen.begin()->first, 3);
}

// The SR lists every candidate with its point in the source's frame of reference (pydicom reads
// the points back within 0.1 mm), its diameter, distance from the rectum and score; it and the
// Secondary Capture of an RGB picture pass dciodvfy without errors.
TEST_F(DicomResults, SrPointsRoundTripAndSrAndScAreValid) {
  const SourceSeries src = read_source_series(dir_ / "ct");
  std::vector<SrCandidate> cands(3);
  cands[0] = {1, {-12.34, 56.78, -250.5}, 7.5, 0.91, 42.3, ""};
  cands[1] = {2, {0.05, -0.05, -280.0}, 5.0, 0.5, std::nullopt, "prone candidate 4"};
  cands[2] = {3, {101.25, 33.3, -210.75}, 12.25, std::nullopt, 130.0, "supine only"};
  write_candidates_sr(cands, src, dir_ / "sr.dcm");
  const auto [code, out] = shell(std::string(COLONFLAT_PYDICOM_PYTHON) + " " + COLONFLAT_SOURCE_DIR +
                                 "/modules/dicom/test/read_sr.py " + (dir_ / "sr.dcm").string());
  if (code != 0 && out.find("No module named") != std::string::npos) GTEST_SKIP() << "no pydicom: " << out;
  ASSERT_EQ(code, 0) << out;
  std::istringstream in(out);
  std::string line, sop, study, patient;
  std::getline(in, line);
  std::istringstream(line) >> sop >> study >> patient;
  EXPECT_EQ(sop, "1.2.840.10008.5.1.4.1.1.88.34");
  EXPECT_EQ(study, src.study_uid);
  EXPECT_EQ(patient, "SEG-TEST");
  for (const SrCandidate& c : cands) {
    ASSERT_TRUE(std::getline(in, line)) << out;
    std::istringstream f(line);
    std::string ident, frame;
    double x, y, z;
    f >> ident >> x >> y >> z >> frame;
    EXPECT_EQ(ident, "candidate_" + std::to_string(c.id));
    EXPECT_NEAR(x, c.lps_mm[0], 0.1);
    EXPECT_NEAR(y, c.lps_mm[1], 0.1);
    EXPECT_NEAR(z, c.lps_mm[2], 0.1);
    EXPECT_EQ(frame, src.frame_of_reference_uid);
    std::ostringstream diameter;
    diameter << "Diameter=" << std::fixed << std::setprecision(1) << c.size_mm;
    EXPECT_NE(line.find(diameter.str()), std::string::npos) << line;
    EXPECT_EQ(line.find("rectum") != std::string::npos, c.from_rectum_cm.has_value()) << line;
  }
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(7, 4, 1);
  image->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
  auto* px = static_cast<unsigned char*>(image->GetScalarPointer());
  for (int i = 0; i < 7 * 4 * 3; ++i) px[i] = static_cast<unsigned char>(i * 3);
  write_secondary_capture(image, src, dir_ / "sc.dcm", "test picture");
  if (shell("command -v dciodvfy").first != 0) GTEST_SKIP() << "dciodvfy (dicom3tools) not installed";
  for (const char* f : {"sr.dcm", "sc.dcm"})
    EXPECT_EQ(dciodvfy_errors(dir_ / f), "") << shell("dciodvfy " + (dir_ / f).string()).second;
}

// An empty mask is refused (a SEG needs a frame), and nothing is written.
TEST_F(DicomResults, EmptyMaskRefused) {
  mask_->FillBuffer(0);
  EXPECT_THROW(write_lumen_seg(mask_.GetPointer(), read_source_series(dir_ / "ct"), dir_ / "e.dcm"), Error);
  EXPECT_FALSE(fs::exists(dir_ / "e.dcm"));
}

}  // namespace
}  // namespace cf
