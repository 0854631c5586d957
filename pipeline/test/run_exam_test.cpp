// `colonflat run EXAM -o OUT` (issue 28 items 1 and 4): the phantom exam (`phantom --exam`: a
// localizer, the supine and the prone scan in nested folders) runs both scans and registers them
// without any option, records which series were used and why not the localizer, and writes the
// DICOM results of each scan; a folder with two patients is refused with the list.
#include <dcmtk/config/osconfig.h>
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "colonflat/core/stage.h"
#include "colonflat/pipeline/registry.h"
#include "colonflat/testing/command.h"
#include "colonflat/testing/files.h"
#include "colonflat/testing/temp_dir.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

class RunExam : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!find_stage("render")) GTEST_SKIP() << "this build lacks the render stage";
    const auto p = testing::run_colonflat({"phantom", "--exam", "-o", dir_.str("ph"), "--seed", "2", "--size", "small", "-q"});
    ASSERT_EQ(p.code, 0) << p.err;
  }
  testing::TempDir dir_;
};

// The exam: three series in EXAM/ST0/SE1..3; `run` chooses supine and prone, runs both, registers
// them, writes each scan's SEG, SR and SC, and says (stderr and run_report.json) why series 1 was
// not used.
TEST_F(RunExam, PhantomExamRunsBothScansAndRegisters) {
  for (const char* f : {"exam/ST0/SE1", "exam/ST0/SE2", "exam/ST0/SE3", "supine/lumen_mask.nrrd", "prone/polyps.json"})
    ASSERT_TRUE(fs::exists(dir_ / "ph" / f)) << f;
  const auto r = testing::run_colonflat({"run", dir_.str("ph/exam"), "-o", dir_.str("out"), "--set",
                                         "render.snapshots=false"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("used (supine): series 2"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("used (prone): series 3"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("not used: series 1 'ColonFlat phantom localizer' (HFS, 1 slice"), std::string::npos) << r.err;
  for (const char* f : {"supine/flat.vtp", "prone/candidates.json", "registration/registration.json",
                        "supine/dicom/seg.dcm", "supine/dicom/candidates_sr.dcm", "supine/dicom/colon_image_sc.dcm",
                        "prone/dicom/seg.dcm"})
    EXPECT_TRUE(fs::exists(dir_ / "out" / f)) << f;
  const nlohmann::json report = nlohmann::json::parse(testing::slurp(dir_ / "out" / "prone" / "run_report.json"));
  ASSERT_TRUE(report.contains("exam")) << report.dump(1);
  EXPECT_EQ(report["exam"]["used"][1]["as"], "prone");
  EXPECT_EQ(report["exam"]["used"][1]["series_number"], 3);
  ASSERT_EQ(report["exam"]["not_used"].size(), 1u);
  EXPECT_NE(report["exam"]["not_used"][0]["reason"].get<std::string>().find("localizer"), std::string::npos);
  // Each supine candidate's SR entry says how it pairs (text values are plain ASCII in the file).
  const std::string sr = testing::slurp(dir_ / "out" / "supine" / "dicom" / "candidates_sr.dcm");
  auto count = [&](const std::string& w) {
    std::size_t n = 0;
    for (auto at = sr.find(w); at != std::string::npos; at = sr.find(w, at + 1)) ++n;
    return n;
  };
  const nlohmann::json cands = nlohmann::json::parse(testing::slurp(dir_ / "out" / "supine" / "candidates.json"));
  EXPECT_EQ(count("prone candidate ") + count("supine only"), cands["candidates"].size());
}

// The prone scan relabelled as another patient: refused before any work, naming both patients.
TEST_F(RunExam, TwoPatientsRefusedWithTheList) {
  for (const auto& e : fs::directory_iterator(dir_ / "ph" / "exam" / "ST0" / "SE3")) {
    DcmFileFormat ff;
    ASSERT_TRUE(ff.loadFile(e.path().c_str()).good());
    ff.getDataset()->putAndInsertString(DCM_PatientID, "OTHER");
    ASSERT_TRUE(ff.saveFile(e.path().c_str()).good());
  }
  const auto r = testing::run_colonflat({"run", dir_.str("ph/exam"), "-o", dir_.str("out"), "-q"});
  EXPECT_EQ(r.code, 3) << r.err;
  EXPECT_EQ(r.err, "colonflat run: error: " + dir_.str("ph/exam") +
                       ": holds 2 patients (CF-PHANTOM (PHANTOM^COLONFLAT): 2 series, OTHER (PHANTOM^COLONFLAT): 1 "
                       "series); give one patient's exam\n");
  EXPECT_FALSE(fs::exists(dir_ / "out"));
}

}  // namespace
}  // namespace cf
