#pragma once
// A DICOM exam as a PACS exports it (a folder of nested folders, EXAM/ST0/SE1/IM0000, or a
// DICOMDIR): every series found, the CT colonography scans chosen among them by rules that say
// why each other series was left out (docs/pacs.md).
//
//   cf::ExamChoice c = cf::choose_exam_scans(cf::scan_exam("EXAM/"));
//   c.supine->input_path();   // "EXAM/ST0/SE2/<SeriesInstanceUID>": what read_ct_volume reads
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace cf {

// One series of the exam, from the headers of its files (no pixel data read).
struct ExamSeries {
  std::string uid;                 // SeriesInstanceUID (0020,000E)
  std::string study_uid;           // StudyInstanceUID (0020,000D)
  std::string patient_id;          // PatientID (0010,0020)
  std::string patient_name;        // PatientName (0010,0010)
  std::string modality;            // Modality (0008,0060)
  std::string image_type;          // ImageType (0008,0008), e.g. ORIGINAL\PRIMARY\AXIAL
  std::string position;            // PatientPosition (0018,5100): HFS, FFS, HFP, FFP, HFDR, ...
  std::string description;         // SeriesDescription (0008,103E)
  int number = 0;                  // SeriesNumber (0020,0011)
  std::filesystem::path folder;    // the folder holding the series' files
  std::vector<std::filesystem::path> files;
  bool same_folder = true;         // every file of the series in `folder`
  double thickness_mm = 0;         // SliceThickness (0018,0050), else the slice spacing
  double coverage_mm = 0;          // extent of the slice positions along the slice normal
  double axis_cosine = 0;          // |cosine| between the slice normal and the patient's head-feet axis
  // What read_ct_volume reads for this series: "FOLDER/UID".
  std::filesystem::path input_path() const { return folder / uid; }
  // "supine", "prone", "decubitus" or "" (PatientPosition missing or unknown).
  std::string posture() const;
  std::string label() const;  // "series 3 'Abdomen supine' (HFS, 128 slices, 3.1 mm)"
};

// Every series below `exam` (a folder searched recursively, or a DICOMDIR file: its folder),
// ordered by SeriesNumber then UID. Files that are not DICOM are skipped. Throws InputError when
// nothing below it is a DICOM file.
std::vector<ExamSeries> scan_exam(const std::filesystem::path& exam);

// True when `path` is a DICOMDIR file or a folder with DICOM files in a subfolder (an exam as a
// PACS exports it): the input of `colonflat run EXAM -o OUT`.
bool is_dicom_exam(const std::filesystem::path& path);

// The rules of the choice (docs/pacs.md gives the physical reason of each default).
struct ExamRules {
  double min_coverage_mm = 200;   // a CTC scan covers the colon: rectum to splenic flexure
  double min_axis_cosine = 0.87;  // axial: slice normal within 30 degrees (maximal gantry tilt) of head-feet
  int min_slices = 10;            // fewer is a scout, a dose-check slice or a partial rescan
};

// The scans to run, and why every other series was left out.
struct ExamChoice {
  std::vector<ExamSeries> series;      // every series found
  std::optional<ExamSeries> supine;    // the first scan (supine, or the only posture there is)
  std::optional<ExamSeries> prone;     // the second scan of a supine + prone exam
  std::vector<std::pair<std::string, std::string>> not_used;  // (series UID, reason)
  std::string first_posture;           // "supine", "prone" or "decubitus": the posture of `supine`
  bool two_scans() const { return supine && prone; }
  nlohmann::json to_json() const;      // for run_report.json
  std::string text() const;            // the lines `run` prints
};

// Chooses the CT colonography scans: Modality CT, not a localizer (ImageType), axial, at least
// `min_slices` slices covering `min_coverage_mm`; grouped by posture (PatientPosition); of two
// scans of one posture the thinner slices (then more slices, then the lower series number).
// Supine and prone: both. Otherwise the one posture there is (supine before prone before
// decubitus). Throws InputError naming `exam` when the series belong to several patients or
// studies (with the list), or when no series is a CT colonography scan (with every reason).
ExamChoice choose_exam_scans(const std::filesystem::path& exam, const std::vector<ExamSeries>& series,
                             const ExamRules& rules = {});

}  // namespace cf
