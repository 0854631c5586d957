// Exam input (issue 28 item 1): the CT colonography scans of a PACS-style exam folder are chosen
// by modality, ImageType, orientation, coverage and PatientPosition, and every other series gets
// its reason; mixed patients or studies are refused with the list.
#include <dcmtk/config/osconfig.h>
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <gtest/gtest.h>

#include <fstream>

#include "colonflat/core/error.h"
#include "colonflat/dicom/exam.h"
#include "colonflat/testing/temp_dir.h"
#include "colonflat/volume/volume_io.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

struct SeriesSpec {
  std::string folder;         // below the exam, e.g. "ST0/SE2"
  int slices = 45;
  double spacing_mm = 5.0;    // 45 x 5 mm: 220 mm, a whole abdomen
  std::string position = "HFS";
  std::string image_type;     // "" keeps ORIGINAL\PRIMARY\AXIAL
  std::string modality;       // "" keeps CT
  std::string patient_id = "CF-PHANTOM";
  std::string study_uid = "1.2.826.0.1.3680043.8.498.1";
  bool sagittal = false;      // slices stacked along the left-right axis
  int number = 1;
};

// Writes a tiny series (4 x 4 pixels a slice) as a PACS exports it: one file per slice.
void write_series(const fs::path& exam, const SeriesSpec& s) {
  auto img = CtImage::New();
  CtImage::SizeType size{{4, 4, static_cast<itk::SizeValueType>(s.slices)}};
  img->SetRegions(size);
  CtImage::SpacingType sp;
  sp[0] = sp[1] = 2.0;
  sp[2] = s.spacing_mm;
  img->SetSpacing(sp);
  if (s.sagittal) {  // slice normal along L (x), rows along P, columns along S
    CtImage::DirectionType d;
    d.Fill(0);
    d[1][0] = 1;
    d[2][1] = 1;
    d[0][2] = 1;
    img->SetDirection(d);
  }
  img->Allocate();
  img->FillBuffer(-1000.f);
  DicomWriteOptions w;
  w.study_uid = s.study_uid;
  w.series_uid = "1.2.826.0.1.3680043.8.498.1." + std::to_string(std::hash<std::string>{}(s.folder) % 100000000);
  w.frame_of_reference_uid = w.series_uid + ".9";
  w.patient_id = s.patient_id;
  w.patient_position = s.position;
  w.series_description = s.folder;
  write_dicom_series(img.GetPointer(), exam / s.folder, w);
  for (const auto& f : fs::directory_iterator(exam / s.folder)) {  // what the writer does not set
    DcmFileFormat ff;
    ASSERT_TRUE(ff.loadFile(f.path().c_str()).good());
    DcmDataset* ds = ff.getDataset();
    ds->putAndInsertString(DCM_SeriesNumber, std::to_string(s.number).c_str());
    if (!s.image_type.empty()) ds->putAndInsertString(DCM_ImageType, s.image_type.c_str());
    if (!s.modality.empty()) ds->putAndInsertString(DCM_Modality, s.modality.c_str());
    ASSERT_TRUE(ff.saveFile(f.path().c_str()).good());
  }
}

const std::pair<std::string, std::string>* reason_for(const ExamChoice& c, const std::string& description) {
  for (const auto& n : c.not_used)
    for (const auto& s : c.series)
      if (s.uid == n.first && s.description == description) return &n;
  return nullptr;
}

class DicomExam : public ::testing::Test {
 protected:
  testing::TempDir dir_;
  fs::path exam_ = dir_ / "EXAM";
};

// A PACS export (localizer, two supine reconstructions, prone, a sagittal reformat, an SR-like
// non-CT series, a short rescan): supine (the thinner one) and prone are used, and every other
// series has the reason it was left out.
TEST_F(DicomExam, ChoosesSupineAndProneAndSaysWhyNotTheOthers) {
  write_series(exam_, {"ST0/SE1", 2, 5.0, "HFS", "ORIGINAL\\PRIMARY\\LOCALIZER", "", "CF-PHANTOM",
                       "1.2.826.0.1.3680043.8.498.1", false, 1});
  write_series(exam_, {"ST0/SE2", 45, 5.0, "HFS", "", "", "CF-PHANTOM", "1.2.826.0.1.3680043.8.498.1", false, 2});
  write_series(exam_, {"ST0/SE3", 89, 2.5, "FFS", "", "", "CF-PHANTOM", "1.2.826.0.1.3680043.8.498.1", false, 3});
  write_series(exam_, {"ST0/SE4", 45, 5.0, "HFP", "", "", "CF-PHANTOM", "1.2.826.0.1.3680043.8.498.1", false, 4});
  write_series(exam_, {"ST0/SE5", 45, 5.0, "HFS", "", "", "CF-PHANTOM", "1.2.826.0.1.3680043.8.498.1", true, 5});
  write_series(exam_, {"ST0/SE6", 45, 5.0, "HFS", "", "OT", "CF-PHANTOM", "1.2.826.0.1.3680043.8.498.1", false, 6});
  write_series(exam_, {"ST0/SE7", 20, 5.0, "HFP", "", "", "CF-PHANTOM", "1.2.826.0.1.3680043.8.498.1", false, 7});
  std::ofstream(exam_ / "README.TXT") << "not DICOM\n";
  ASSERT_TRUE(is_dicom_exam(exam_));
  const ExamChoice c = choose_exam_scans(exam_, scan_exam(exam_));
  ASSERT_EQ(c.series.size(), 7u);
  ASSERT_TRUE(c.two_scans());
  EXPECT_EQ(c.supine->description, "ST0/SE3");  // 2.5 mm beats 5 mm
  EXPECT_EQ(c.prone->description, "ST0/SE4");
  EXPECT_EQ(c.supine->input_path(), exam_ / "ST0/SE3" / c.supine->uid);
  ASSERT_EQ(c.not_used.size(), 5u) << c.text();
  const std::vector<std::pair<std::string, std::string>> expected = {
      {"ST0/SE1", "a localizer"},
      {"ST0/SE2", "thinner slices (2.50 mm against 5.00 mm)"},
      {"ST0/SE5", "not axial (slice normal 90 degrees"},
      {"ST0/SE6", "modality OT, not CT"},
      {"ST0/SE7", "covers 95 mm along the body"}};
  for (const auto& [description, words] : expected) {
    const auto* r = reason_for(c, description);
    ASSERT_NE(r, nullptr) << description << "\n" << c.text();
    EXPECT_NE(r->second.find(words), std::string::npos) << description << ": " << r->second;
  }
  const nlohmann::json j = c.to_json();
  EXPECT_EQ(j["used"].size(), 2u);
  EXPECT_EQ(j["used"][0]["as"], "supine");
  EXPECT_EQ(j["not_used"].size(), 5u);
}

// One scan (supine only, beside its localizer): the one-scan run, reached through the DICOMDIR
// file's folder as well.
TEST_F(DicomExam, OneScanAndDicomdir) {
  write_series(exam_, {"DICOM/ST0/SE1", 2, 5.0, "HFS", "ORIGINAL\\PRIMARY\\LOCALIZER"});
  write_series(exam_, {"DICOM/ST0/SE2", 45, 5.0, "HFP"});
  std::ofstream(exam_ / "DICOMDIR") << "";  // the folder is what counts
  ASSERT_TRUE(is_dicom_exam(exam_ / "DICOMDIR"));
  const ExamChoice c = choose_exam_scans(exam_ / "DICOMDIR", scan_exam(exam_ / "DICOMDIR"));
  ASSERT_TRUE(c.supine);
  EXPECT_FALSE(c.two_scans());
  EXPECT_EQ(c.first_posture, "prone");
  EXPECT_NE(c.text().find("used (prone)"), std::string::npos) << c.text();
}

// Two patients (or two studies) in one folder: refused, naming each with its series count.
TEST_F(DicomExam, MixedPatientsAndStudiesRefusedWithTheList) {
  write_series(exam_, {"A/SE1", 45, 5.0, "HFS", "", "", "PAT-A"});
  write_series(exam_, {"B/SE1", 45, 5.0, "HFP", "", "", "PAT-B"});
  try {
    choose_exam_scans(exam_, scan_exam(exam_));
    FAIL() << "two patients accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.problem(), "holds 2 patients (PAT-A (PHANTOM^COLONFLAT): 1 series, PAT-B (PHANTOM^COLONFLAT): 1 series); give one patient's exam");
  }
  const fs::path studies = dir_ / "STUDIES";
  write_series(studies, {"A/SE1", 45, 5.0, "HFS", "", "", "P", "1.2.3.1"});
  write_series(studies, {"B/SE1", 45, 5.0, "HFP", "", "", "P", "1.2.3.2"});
  try {
    choose_exam_scans(studies, scan_exam(studies));
    FAIL() << "two studies accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.problem(), "holds 2 studies (1.2.3.1: 1 series, 1.2.3.2: 1 series); give one study");
  }
}

// No usable scan: the error lists every series with its reason; a folder without DICOM says so.
TEST_F(DicomExam, NoScanGivesEveryReason) {
  write_series(exam_, {"S/SE1", 2, 5.0, "HFS", "ORIGINAL\\PRIMARY\\LOCALIZER"});
  try {
    choose_exam_scans(exam_, scan_exam(exam_));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(e.problem().find("no CT colonography scan among its 1 series"), std::string::npos) << e.what();
    EXPECT_NE(e.problem().find("a localizer"), std::string::npos) << e.what();
  }
  fs::create_directories(dir_ / "empty/sub");
  std::ofstream(dir_ / "empty/sub/x.txt") << "text";
  EXPECT_FALSE(is_dicom_exam(dir_ / "empty"));
  EXPECT_THROW(scan_exam(dir_ / "empty"), InputError);
}

}  // namespace
}  // namespace cf
