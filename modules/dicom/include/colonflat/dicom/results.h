#pragma once
// DICOM results of a run, in the source study (docs/pacs.md): a Segmentation (SEG) of the colon
// lumen on the source CT's slices, a Comprehensive 3D SR of the polyp candidates, and a Secondary
// Capture of the flat colon image. Each object gets the source's PatientID, StudyInstanceUID and
// FrameOfReferenceUID, a new series, and references to the source images.
//
//   cf::SourceSeries src = cf::read_source_series("EXAM/ST0/SE2/1.2.3");   // what the run read
//   cf::write_lumen_seg(mask, src, "OUT/dicom/seg.dcm");
#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "colonflat/volume/volume_io.h"

class vtkImageData;

namespace cf {

// One image of the source series.
struct SourceSlice {
  std::string sop_class_uid, sop_instance_uid;
  std::array<double, 3> position{};  // ImagePositionPatient, LPS mm
  double along = 0;                  // position along the slice normal, mm
};

// The CT series a run read, from its file headers.
struct SourceSeries {
  std::string patient_id, patient_name, patient_birth_date, patient_sex;
  std::string study_uid, study_id, study_date, study_time, accession_number, referring_physician;
  std::string series_uid, frame_of_reference_uid, patient_position;
  std::array<double, 6> orientation{};  // ImageOrientationPatient
  std::array<double, 3> normal{};       // row x column direction
  std::vector<SourceSlice> slices;      // ordered along the normal
  std::filesystem::path first_file;
  // The slice at `along` mm on the normal (within a tenth of the slice gap); nullptr when none.
  const SourceSlice* slice_at(double along) const;
};

// Reads the headers of the series a run read: "DIR/UID" (a series in DIR) or a folder holding one
// series. Throws InputError when it is not a DICOM series.
SourceSeries read_source_series(const std::filesystem::path& input);

// True when `input` (a run's input) names a DICOM series: "DIR/UID" or a folder of DICOM files.
bool is_dicom_series_input(const std::filesystem::path& input);

// A new UID under this implementation's root (random, DCMTK's generator).
std::string new_uid();

// The lumen mask as a binary SEG: one frame per source slice that holds lumen, each with its
// plane position and a reference to its source image (derivation image), the segment coded
// "Colon" (SCT 71854001). The mask must lie on the source's grid (it is the segment stage's
// output on that CT). Written atomically. Returns the SEG's SOPInstanceUID.
std::string write_lumen_seg(const MaskImage* mask, const SourceSeries& src, const std::filesystem::path& file,
                            int series_number = 901);

// One polyp candidate of the structured report.
struct SrCandidate {
  int id = 0;
  std::array<double, 3> lps_mm{};       // the candidate's point, LPS mm (the source's frame of reference)
  double size_mm = 0;                   // estimated diameter
  std::optional<double> score;          // detection score 0..1
  std::optional<double> from_rectum_cm; // position along the colon from the rectal end
  std::string pairing;                  // "prone candidate 2 (12.0 mm apart)", "supine only", ... ("" = one scan)
};

// The candidates as a Comprehensive 3D SR in the source study (new series): a "Finding" container
// a candidate with its tracking identifier, SCOORD3D point, diameter (mm), distance from the
// rectum (cm), score and pairing. Written atomically; returns the SR's SOPInstanceUID.
std::string write_candidates_sr(const std::vector<SrCandidate>& candidates, const SourceSeries& src,
                                const std::filesystem::path& file, int series_number = 902);

// An 8-bit RGB picture (VTK image, rows from the bottom; e.g. the flat colon image) as a Secondary
// Capture image in the source study (new series, Modality OT, burned-in annotation). Written
// atomically; returns its SOPInstanceUID.
std::string write_secondary_capture(vtkImageData* image, const SourceSeries& src, const std::filesystem::path& file,
                                    const std::string& description, int series_number = 903);

}  // namespace cf
