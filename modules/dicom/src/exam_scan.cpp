// Every series below an exam folder (or a DICOMDIR's folder), from the file headers (DCMTK,
// parsing stops before the pixel data).
#include <dcmtk/config/osconfig.h>
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcmetinf.h>
#include <dcmtk/dcmdata/dcuid.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include "colonflat/core/error.h"
#include "colonflat/dicom/exam.h"
#include "dicom_common.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

// The header values of one file that the choice needs.
struct FileHeader {
  std::string series, study, patient_id, patient_name, modality, image_type, position, description;
  int number = 0;
  double thickness = 0;
  std::vector<double> ipp, iop;
};

// The header of a Part 10 file ("DICM" after the preamble); nullopt for anything else, a DICOMDIR
// included.
std::optional<FileHeader> read_header(const fs::path& file) {
  if (!dicom::has_part10_magic(file)) return std::nullopt;
  DcmFileFormat ff;
  if (ff.loadFileUntilTag(file.c_str(), EXS_Unknown, EGL_noChange, DCM_MaxReadLength, ERM_fileOnly,
                          DCM_PixelData).bad())
    return std::nullopt;
  if (dicom::text(ff.getMetaInfo(), DCM_MediaStorageSOPClassUID) == UID_MediaStorageDirectoryStorage) return std::nullopt;
  DcmDataset* ds = ff.getDataset();
  FileHeader h;
  h.series = dicom::text(ds, DCM_SeriesInstanceUID);
  if (h.series.empty()) return std::nullopt;
  h.study = dicom::text(ds, DCM_StudyInstanceUID);
  h.patient_id = dicom::text(ds, DCM_PatientID);
  h.patient_name = dicom::text(ds, DCM_PatientName);
  h.modality = dicom::text(ds, DCM_Modality);
  h.image_type = dicom::text(ds, DCM_ImageType);
  h.position = dicom::text(ds, DCM_PatientPosition);
  h.description = dicom::text(ds, DCM_SeriesDescription);
  h.number = std::atoi(dicom::text(ds, DCM_SeriesNumber).c_str());
  h.thickness = std::strtod(dicom::text(ds, DCM_SliceThickness).c_str(), nullptr);
  h.ipp = dicom::numbers(dicom::text(ds, DCM_ImagePositionPatient));
  h.iop = dicom::numbers(dicom::text(ds, DCM_ImageOrientationPatient));
  return h;
}

// The series' geometry from its slices: extent along the slice normal, slice spacing, and how
// close the normal is to the head-feet axis (LPS z).
void measure_geometry(ExamSeries& s, const std::vector<FileHeader>& slices) {
  const std::vector<double>& o = slices.front().iop;
  if (o.size() != 6) return;
  const double n[3] = {o[1] * o[5] - o[2] * o[4], o[2] * o[3] - o[0] * o[5], o[0] * o[4] - o[1] * o[3]};
  const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  if (len < 1e-6) return;
  s.axis_cosine = std::abs(n[2]) / len;
  std::vector<double> along;
  for (const auto& h : slices)
    if (h.ipp.size() == 3) along.push_back((h.ipp[0] * n[0] + h.ipp[1] * n[1] + h.ipp[2] * n[2]) / len);
  if (along.size() < 2) return;
  std::sort(along.begin(), along.end());
  s.coverage_mm = along.back() - along.front();
  if (s.thickness_mm <= 0) s.thickness_mm = s.coverage_mm / double(along.size() - 1);
}

ExamSeries make_series(const std::vector<std::pair<fs::path, FileHeader>>& files) {
  const FileHeader& h = files.front().second;
  ExamSeries s;
  s.uid = h.series;
  s.study_uid = h.study;
  s.patient_id = h.patient_id;
  s.patient_name = h.patient_name;
  s.modality = h.modality;
  s.image_type = h.image_type;
  s.position = h.position;
  s.description = h.description;
  s.number = h.number;
  s.thickness_mm = h.thickness;
  s.folder = files.front().first.parent_path();
  std::vector<FileHeader> slices;
  for (const auto& [path, header] : files) {
    s.files.push_back(path);
    s.same_folder = s.same_folder && path.parent_path() == s.folder;
    slices.push_back(header);
  }
  measure_geometry(s, slices);
  return s;
}

}  // namespace

bool is_dicom_exam(const fs::path& path) {
  std::error_code ec;
  if (fs::is_regular_file(path, ec)) return dicom::upper(path.filename().string()) == "DICOMDIR";
  if (!fs::is_directory(path, ec)) return false;
  for (auto it = fs::recursive_directory_iterator(path, fs::directory_options::skip_permission_denied, ec);
       it != fs::recursive_directory_iterator(); it.increment(ec)) {
    if (ec) break;
    if (it.depth() >= 1 && it->is_regular_file(ec) && dicom::has_part10_magic(it->path())) return true;
  }
  return false;
}

std::vector<ExamSeries> scan_exam(const fs::path& exam) {
  dicom::quiet_dcmtk();
  std::error_code ec;
  const fs::path root = fs::is_regular_file(exam, ec) ? exam.parent_path() : exam;
  if (!fs::is_directory(root, ec)) throw InputError(exam.string(), "no such folder");
  std::map<std::string, std::vector<std::pair<fs::path, FileHeader>>> by_series;
  for (auto it = fs::recursive_directory_iterator(root, fs::directory_options::skip_permission_denied, ec);
       it != fs::recursive_directory_iterator(); it.increment(ec)) {
    if (ec) throw InputError(exam.string(), "cannot list " + it->path().string() + ": " + ec.message());
    if (!it->is_regular_file(ec)) continue;
    if (auto h = read_header(it->path())) by_series[h->series].emplace_back(it->path(), *h);
  }
  if (by_series.empty()) throw InputError(exam.string(), "holds no DICOM file (searched every subfolder)");
  std::vector<ExamSeries> out;
  for (auto& [uid, files] : by_series) {
    std::sort(files.begin(), files.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    out.push_back(make_series(files));
  }
  std::sort(out.begin(), out.end(), [](const ExamSeries& a, const ExamSeries& b) {
    return a.number != b.number ? a.number < b.number : a.uid < b.uid;
  });
  return out;
}

}  // namespace cf
