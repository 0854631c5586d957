// The CT series a run read (headers only): what every result object copies and references.
#include <dcmtk/config/osconfig.h>
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcuid.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "colonflat/core/error.h"
#include "colonflat/dicom/results.h"
#include "dicom_common.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

// The study, patient and series level values, from the first file.
void take_series_values(SourceSeries& s, DcmDataset* ds) {
  s.patient_id = dicom::text(ds, DCM_PatientID);
  s.patient_name = dicom::text(ds, DCM_PatientName);
  s.patient_birth_date = dicom::text(ds, DCM_PatientBirthDate);
  s.patient_sex = dicom::text(ds, DCM_PatientSex);
  s.study_uid = dicom::text(ds, DCM_StudyInstanceUID);
  s.study_id = dicom::text(ds, DCM_StudyID);
  s.study_date = dicom::text(ds, DCM_StudyDate);
  s.study_time = dicom::text(ds, DCM_StudyTime);
  s.accession_number = dicom::text(ds, DCM_AccessionNumber);
  s.referring_physician = dicom::text(ds, DCM_ReferringPhysicianName);
  s.series_uid = dicom::text(ds, DCM_SeriesInstanceUID);
  s.frame_of_reference_uid = dicom::text(ds, DCM_FrameOfReferenceUID);
  s.patient_position = dicom::text(ds, DCM_PatientPosition);
  const std::vector<double> o = dicom::numbers(dicom::text(ds, DCM_ImageOrientationPatient));
  if (o.size() == 6) std::copy(o.begin(), o.end(), s.orientation.begin());
  const auto& r = s.orientation;
  s.normal = {r[1] * r[5] - r[2] * r[4], r[2] * r[3] - r[0] * r[5], r[0] * r[4] - r[1] * r[3]};
}

}  // namespace

const SourceSlice* SourceSeries::slice_at(double along) const {
  if (slices.empty()) return nullptr;
  const double gap = slices.size() > 1 ? (slices.back().along - slices.front().along) / double(slices.size() - 1) : 1.0;
  const auto it = std::min_element(slices.begin(), slices.end(), [&](const SourceSlice& a, const SourceSlice& b) {
    return std::abs(a.along - along) < std::abs(b.along - along);
  });
  return std::abs(it->along - along) <= 0.1 * std::abs(gap) ? &*it : nullptr;
}

bool is_dicom_series_input(const fs::path& input) {
  std::error_code ec;
  if (fs::is_directory(input, ec)) {
    for (const auto& e : fs::directory_iterator(input, ec))
      if (e.is_regular_file(ec) && dicom::has_part10_magic(e.path())) return true;
    return false;
  }
  return !fs::exists(input, ec) && input.has_parent_path() && fs::is_directory(input.parent_path(), ec) &&
         input.filename().string().find_first_not_of("0123456789.") == std::string::npos;
}

SourceSeries read_source_series(const fs::path& input) {
  dicom::quiet_dcmtk();
  std::error_code ec;
  const bool folder = fs::is_directory(input, ec);
  const fs::path dir = folder ? input : input.parent_path();
  const std::string uid = folder ? "" : input.filename().string();
  SourceSeries s;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    if (!e.is_regular_file(ec) || !dicom::has_part10_magic(e.path())) continue;
    DcmFileFormat ff;
    if (ff.loadFileUntilTag(e.path().c_str(), EXS_Unknown, EGL_noChange, DCM_MaxReadLength, ERM_fileOnly,
                            DCM_PixelData).bad())
      continue;
    DcmDataset* ds = ff.getDataset();
    const std::string series = dicom::text(ds, DCM_SeriesInstanceUID);
    if (!uid.empty() && series != uid) continue;
    if (s.slices.empty()) take_series_values(s, ds), s.first_file = e.path();
    if (series != s.series_uid) throw InputError(dir.string(), "holds several series; name one as DIR/UID");
    const std::vector<double> p = dicom::numbers(dicom::text(ds, DCM_ImagePositionPatient));
    if (p.size() != 3) throw InputError(e.path().string(), "no ImagePositionPatient (0020,0032)");
    SourceSlice slice{dicom::text(ds, DCM_SOPClassUID), dicom::text(ds, DCM_SOPInstanceUID), {p[0], p[1], p[2]},
                      p[0] * s.normal[0] + p[1] * s.normal[1] + p[2] * s.normal[2]};
    s.slices.push_back(slice);
  }
  if (s.slices.empty()) throw InputError(input.string(), "no DICOM series here");
  std::sort(s.slices.begin(), s.slices.end(), [](const SourceSlice& a, const SourceSlice& b) { return a.along < b.along; });
  return s;
}

std::string new_uid() {
  char buf[100];
  dcmGenerateUniqueIdentifier(buf, SITE_INSTANCE_UID_ROOT);
  return buf;
}

}  // namespace cf
