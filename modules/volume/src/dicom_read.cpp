// DICOM series folders: scan, choose a series, order and check its slices, read through GDCM.
#include <gdcmDirectory.h>
#include <gdcmReader.h>
#include <gdcmScanner.h>
#include <gdcmTrace.h>
#include <itkGDCMImageIO.h>
#include <itkImageFileReader.h>
#include <itkImageFileWriter.h>
#include <itkImageRegionConstIterator.h>
#include <itkImageSeriesReader.h>
#include <itkImageSeriesWriter.h>
#include <itkMetaDataObject.h>
#include <itkMetaImageIO.h>
#include <itkNiftiImageIO.h>
#include <itkNrrdImageIO.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <mutex>
#include <sstream>

#include "colonflat/core/atomic_file.h"
#include "colonflat/core/error.h"

#include <set>

#include "colonflat/core/memory_budget.h"
#include "volume_internal.h"

namespace cf {
namespace vio {
namespace {

// ---------------------------------------------------------------------------------------------
// DICOM folders

struct DicomFile {
  std::string name;
  double position = 0;  // along the slice normal, mm
};

const gdcm::Tag kSeriesUid(0x0020, 0x000e), kIpp(0x0020, 0x0032), kIop(0x0020, 0x0037), kSopClass(0x0008, 0x0016),
    kModality(0x0008, 0x0060), kFrames(0x0028, 0x0008), kDescription(0x0008, 0x103e), kTransferSyntax(0x0002, 0x0010);


std::string fname(const std::string& p) { return fs::path(p).filename().string(); }

// Orders a series by position along the slice normal and checks the gaps; returns the files.
std::vector<std::string> sorted_checked_series(const fs::path& dir, const ScannedFolder& f,
                                               const std::vector<std::string>& files, const VolumeReadOptions& opts) {
  const std::string where = dir.string();
  const std::string first = files.front();
  const std::string sop = trim(f.scanner.GetValue(first.c_str(), kSopClass));
  const std::string frames = trim(f.scanner.GetValue(first.c_str(), kFrames));
  if (sop == kEnhancedCtSop || (!frames.empty() && std::atoi(frames.c_str()) > 1))
    throw InputError(where, fname(first) + " is an enhanced multi-frame CT (" +
                                (frames.empty() ? std::string("several") : frames) +
                                " frames), which is not supported; export a classic single-frame CT series");
  for (const auto& file : files) check_dicom_length(file, where, trim(f.scanner.GetValue(file.c_str(), kTransferSyntax)));
  if (files.size() == 1) return files;
  const std::vector<double> iop = ds_values(trim(f.scanner.GetValue(first.c_str(), kIop)));
  if (iop.size() != 6) throw InputError(where, fname(first) + ": no valid ImageOrientationPatient (0020,0037)");
  const double n[3] = {iop[1] * iop[5] - iop[2] * iop[4], iop[2] * iop[3] - iop[0] * iop[5],
                       iop[0] * iop[4] - iop[1] * iop[3]};
  std::vector<DicomFile> v;
  for (const auto& file : files) {
    const std::vector<double> o = ds_values(trim(f.scanner.GetValue(file.c_str(), kIop)));
    if (o.size() != 6) throw InputError(where, fname(file) + ": no valid ImageOrientationPatient (0020,0037)");
    for (int k = 0; k < 6; ++k)
      if (std::abs(o[k] - iop[k]) > 1e-4)
        throw InputError(where, fname(file) + ": slice orientation differs from " + fname(first) + " (mixed series)");
    const std::vector<double> p = ds_values(trim(f.scanner.GetValue(file.c_str(), kIpp)));
    if (p.size() != 3) throw InputError(where, fname(file) + ": no valid ImagePositionPatient (0020,0032)");
    v.push_back({file, p[0] * n[0] + p[1] * n[1] + p[2] * n[2]});
  }
  std::sort(v.begin(), v.end(), [](const DicomFile& a, const DicomFile& b) { return a.position < b.position; });
  std::vector<double> gaps;
  for (std::size_t i = 0; i + 1 < v.size(); ++i) {
    const double g = v[i + 1].position - v[i].position;
    if (g < 1e-3)
      throw InputError(where, "two slices at the same position " + format_number(v[i].position) + " mm (" +
                                  fname(v[i].name) + ", " + fname(v[i + 1].name) + ")");
    gaps.push_back(g);
  }
  std::vector<double> sorted = gaps;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double med = sorted[sorted.size() / 2];
  for (std::size_t i = 0; i < gaps.size(); ++i) {
    if (std::abs(gaps[i] - med) > opts.slice_gap_tolerance * med) {
      std::ostringstream s;
      s << "uneven slice spacing: gap of " << format_number(gaps[i]) << " mm between " << fname(v[i].name) << " and "
        << fname(v[i + 1].name) << " where the series has " << format_number(med) << " mm";
      if (gaps[i] > 1.5 * med) s << " (about " << std::lround(gaps[i] / med) - 1 << " missing slice(s))";
      throw InputError(where, s.str());
    }
  }
  std::vector<std::string> out;
  for (const auto& d : v) out.push_back(d.name);
  return out;
}

}  // namespace

// GDCM pads truncated pixel data silently: compare the file size with the length its data set
// declares (meta header with preamble, plus the data set with its pixel data). Uncompressed
// transfer syntaxes with a preamble only (else the lengths are not comparable).
void check_dicom_length(const fs::path& file, const std::string& where, const std::string& ts) {
  if (ts != "1.2.840.10008.1.2" && ts != "1.2.840.10008.1.2.1" && ts != "1.2.840.10008.1.2.2") return;
  if (!has_dicom_magic(file)) return;
  gdcm::Reader r;
  r.SetFileName(file.c_str());
  const bool ok = r.Read();
  const gdcm::DataSet& ds = r.GetFile().GetDataSet();
  const double declared = double(r.GetFile().GetHeader().GetFullLength()) +
                          double(ts == "1.2.840.10008.1.2" ? ds.GetLength<gdcm::ImplicitDataElement>()
                                                           : ds.GetLength<gdcm::ExplicitDataElement>());
  std::error_code ec;
  const double have = double(fs::file_size(file, ec));
  if (!ok || (!ec && have < declared))
    throw InputError(where, file.filename().string() + " is truncated (" + format_number(have) +
                                " bytes; its header declares " + format_number(declared) + ")");
}

bool dicom_meta_complete(const fs::path& file) {
  // Preamble (128) + "DICM" + (0002,0000) UL group length: tag 4 + VR 2 + length 2 + value 4.
  std::ifstream in(file, std::ios::binary);
  unsigned char head[144] = {};
  in.read(reinterpret_cast<char*>(head), sizeof head);
  if (in.gcount() != 144 || std::memcmp(head + 128, "DICM", 4) != 0) return false;
  if (!(head[132] == 2 && head[133] == 0 && head[134] == 0 && head[135] == 0 && head[136] == 'U' && head[137] == 'L'))
    return true;  // no group length: GDCM parses element by element
  const std::uint32_t group = head[140] | (head[141] << 8) | (head[142] << 16) | (std::uint32_t(head[143]) << 24);
  std::error_code ec;
  return double(fs::file_size(file, ec)) >= 144.0 + double(group) + 8.0;  // meta group + one data element tag
}

std::string dicom_transfer_syntax(const fs::path& file) {
  gdcm::Reader r;
  r.SetFileName(file.c_str());
  std::set<gdcm::Tag> tags{gdcm::Tag(0x0002, 0x0010)};
  if (!r.ReadSelectedTags(tags)) return "";
  return r.GetFile().GetHeader().GetDataSetTransferSyntax().GetString() ? trim(r.GetFile().GetHeader().GetDataSetTransferSyntax().GetString()) : "";
}

namespace {

std::string series_list_text(const ScannedFolder& f) {
  std::string s;
  for (const auto& [uid, files] : f.series) s += (s.empty() ? "" : ", ") + uid + " (" + std::to_string(files.size()) + " files)";
  return s;
}


}  // namespace

std::unique_ptr<ScannedFolder> scan_folder(const fs::path& dir) {
  quiet_libraries();
  auto f = std::make_unique<ScannedFolder>();
  gdcm::Directory d;
  d.Load(dir.string(), false);
  const auto& files = d.GetFilenames();
  for (const auto& t : {kSeriesUid, kIpp, kIop, kSopClass, kModality, kFrames, kDescription, kTransferSyntax})
    f->scanner.AddTag(t);
  if (files.empty()) return f;
  // GDCM (Debian's build keeps assertions) aborts on a file cut inside its meta header: such files
  // are left out here, so a series with one shows a missing slice.
  std::vector<std::string> complete;
  for (const auto& file : files)
    if (dicom_meta_complete(file)) complete.push_back(file);
  if (complete.empty()) return f;
  f->scanner.Scan(complete);
  for (const auto& file : complete) {
    if (!f->scanner.IsKey(file.c_str())) continue;
    const std::string uid = trim(f->scanner.GetValue(file.c_str(), kSeriesUid));
    f->series[uid].push_back(file);
  }
  return f;
}


bool split_series_path(const fs::path& p, fs::path& dir, std::string& uid) {
  if (fs::exists(p) || !p.has_parent_path()) return false;
  const fs::path parent = p.parent_path();
  if (!fs::is_directory(parent)) return false;
  const std::string last = p.filename().string();
  if (last.empty() || last.find_first_not_of("0123456789.") != std::string::npos) return false;
  dir = parent;
  uid = last;
  return true;
}

DicomChoice choose_series(const fs::path& dir, std::string uid, const VolumeReadOptions& opts, const ScannedFolder& f) {
  const std::string where = dir.string();
  if (f.series.empty()) throw InputError(where, "folder holds no readable DICOM file");
  if (uid.empty()) uid = opts.series_uid;
  if (uid.empty()) {
    if (f.series.size() > 1)
      throw InputError(where, "folder holds " + std::to_string(f.series.size()) + " DICOM series: " +
                                  series_list_text(f) + "; choose one with --series UID or the path DIR/UID");
    uid = f.series.begin()->first;
  }
  auto it = f.series.find(uid);
  if (it == f.series.end())
    throw InputError(where, "no DICOM series with UID " + uid + " (the folder holds: " + series_list_text(f) + ")");
  return {dir, uid, it->second};
}

FloatImage::Pointer read_dicom_series(const DicomChoice& c, const ScannedFolder& f, const VolumeReadOptions& opts) {
  const std::vector<std::string> files = sorted_checked_series(c.dir, f, c.files, opts);
  auto io = itk::GDCMImageIO::New();
  try {  // the memory the series will take, before any slice is read
    auto probe = itk::GDCMImageIO::New();
    probe->SetFileName(files.front());
    probe->ReadImageInformation();
    const double bytes = double(probe->GetDimensions(0)) * double(probe->GetDimensions(1)) * double(files.size()) *
                         double(sizeof(float) + probe->GetComponentSize());
    check_memory_budget(c.dir.string(), "the series (" + std::to_string(probe->GetDimensions(0)) + " x " +
                                            std::to_string(probe->GetDimensions(1)) + " x " +
                                            std::to_string(files.size()) + " voxels)", bytes);
  } catch (const itk::ExceptionObject& e) {
    throw InputError(c.dir.string(), "cannot read DICOM series " + c.uid + ": " + itk_message(e));
  }
  auto reader = itk::ImageSeriesReader<FloatImage>::New();
  reader->SetImageIO(io);
  reader->SetFileNames(files);
  try {
    reader->Update();
  } catch (const itk::ExceptionObject& e) {
    throw InputError(c.dir.string(), "cannot read DICOM series " + c.uid + ": " + itk_message(e));
  }
  FloatImage::Pointer out = reader->GetOutput();
  std::string position;  // PatientPosition of the (last read) slice: one value per series
  if (io->GetValueFromTag("0018|5100", position)) set_patient_position(out.GetPointer(), trim(position.c_str()));
  return out;
}

}  // namespace vio

using namespace vio;

std::vector<DicomSeriesInfo> list_dicom_series(const fs::path& dir) {
  std::vector<DicomSeriesInfo> out;
  if (!fs::is_directory(dir)) return out;
  auto f = scan_folder(dir);
  for (const auto& [uid, files] : f->series) {
    const char* first = files.front().c_str();
    out.push_back({uid, files.size(), trim(f->scanner.GetValue(first, kModality)),
                   trim(f->scanner.GetValue(first, kDescription))});
  }
  return out;
}

}  // namespace cf
