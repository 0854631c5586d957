#include "colonflat/volume/volume_io.h"

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
#include <cctype>
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

namespace fs = std::filesystem;

namespace cf {
namespace {

using ShortImage = itk::Image<std::int16_t, 3>;
using FloatImage = itk::Image<float, 3>;

constexpr const char* kEnhancedCtSop = "1.2.840.10008.5.1.4.1.1.2.1";
constexpr const char* kCtSop = "1.2.840.10008.5.1.4.1.1.2";

void quiet_libraries() {
  static std::once_flag once;
  std::call_once(once, [] {
    itk::Object::GlobalWarningDisplayOff();  // warnings would print to stderr; we report errors ourselves
    gdcm::Trace::WarningOff();
    gdcm::Trace::DebugOff();
    gdcm::Trace::ErrorOff();
  });
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

// ".nii.gz" or the last extension, lower case.
std::string full_ext(const fs::path& p) {
  const std::string n = lower(p.filename().string());
  if (n.size() > 7 && n.compare(n.size() - 7, 7, ".nii.gz") == 0) return ".nii.gz";
  return lower(p.extension().string());
}

// First line of an ITK exception description, without ITK's decoration ("ITK ERROR:",
// "NrrdImageIO(0x55...):") and with a reason where ITK gives none.
std::string itk_message(const itk::ExceptionObject& e) {
  std::string d = e.GetDescription() ? e.GetDescription() : "";
  const auto nl = d.find('\n');
  if (nl != std::string::npos) d = d.substr(0, nl);
  if (d.rfind("ITK ERROR: ", 0) == 0) d = d.substr(11);
  const auto addr = d.find("(0x"), close = d.find("): ");
  if (addr != std::string::npos && close != std::string::npos && addr < close) d = d.substr(close + 3);
  while (!d.empty() && (d.back() == ' ' || d.back() == '.' || d.back() == '\r' || d.back() == ':')) d.pop_back();
  // "Read: Error reading <file>" says nothing more than that the pixel data could not be read.
  if (d.rfind("Read: Error reading", 0) == 0 || d.rfind("Error reading", 0) == 0)
    d = "cannot read the pixel data (truncated or corrupt file)";
  if (d.empty()) d = "unreadable";
  return d;
}

std::string trim(const char* v) {
  if (!v) return "";
  std::string s(v);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\0')) s.pop_back();
  std::size_t b = 0;
  while (b < s.size() && s[b] == ' ') ++b;
  return s.substr(b);
}

// A DICOM multi-valued decimal string "a\b\c" (value representation DS) as numbers.
std::vector<double> ds_values(const std::string& s) {
  std::string t = s;
  std::replace(t.begin(), t.end(), '\\', ' ');
  std::istringstream in(t);
  in.imbue(std::locale::classic());
  std::vector<double> v;
  double x;
  while (in >> x) v.push_back(x);
  return v;
}

bool has_dicom_magic(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  char buf[132];
  if (!in.read(buf, 132)) return false;
  return std::memcmp(buf + 128, "DICM", 4) == 0;
}

itk::ImageIOBase::Pointer io_for(const fs::path& p, bool for_writing) {
  const std::string e = full_ext(p);
  if (e == ".nrrd" || e == ".nhdr") return itk::NrrdImageIO::New().GetPointer();
  if (e == ".nii" || e == ".nii.gz") return itk::NiftiImageIO::New().GetPointer();
  if (e == ".mha" || e == ".mhd") return itk::MetaImageIO::New().GetPointer();
  if (!for_writing && (e == ".dcm" || e == ".ima" || has_dicom_magic(p))) return itk::GDCMImageIO::New().GetPointer();
  return nullptr;
}

const char* kReadFormats = ".nrrd .nhdr .nii .nii.gz .mha .mhd, a DICOM file or a DICOM series folder";
const char* kWriteFormats = ".nrrd .nii .nii.gz .mha";

// ---------------------------------------------------------------------------------------------
// DICOM folders

struct DicomFile {
  std::string name;
  double position = 0;  // along the slice normal, mm
};

struct ScannedFolder {
  std::map<std::string, std::vector<std::string>> series;  // uid -> files
  gdcm::Scanner scanner;
};

const gdcm::Tag kSeriesUid(0x0020, 0x000e), kIpp(0x0020, 0x0032), kIop(0x0020, 0x0037), kSopClass(0x0008, 0x0016),
    kModality(0x0008, 0x0060), kFrames(0x0028, 0x0008), kDescription(0x0008, 0x103e), kTransferSyntax(0x0002, 0x0010);

std::unique_ptr<ScannedFolder> scan_folder(const fs::path& dir) {
  quiet_libraries();
  auto f = std::make_unique<ScannedFolder>();
  gdcm::Directory d;
  d.Load(dir.string(), false);
  const auto& files = d.GetFilenames();
  for (const auto& t : {kSeriesUid, kIpp, kIop, kSopClass, kModality, kFrames, kDescription, kTransferSyntax})
    f->scanner.AddTag(t);
  if (files.empty()) return f;
  f->scanner.Scan(files);
  for (const auto& file : files) {
    if (!f->scanner.IsKey(file.c_str())) continue;
    const std::string uid = trim(f->scanner.GetValue(file.c_str(), kSeriesUid));
    f->series[uid].push_back(file);
  }
  return f;
}

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
  // A truncated file (uncompressed transfer syntaxes).
  for (const auto& file : files) {
    const std::string ts = trim(f.scanner.GetValue(file.c_str(), kTransferSyntax));
    if (ts != "1.2.840.10008.1.2" && ts != "1.2.840.10008.1.2.1" && ts != "1.2.840.10008.1.2.2") continue;
    if (!has_dicom_magic(file)) continue;  // without a preamble the meta length below is not comparable
    // GDCM pads truncated pixel data silently: compare the file size with the length its data set
    // declares (meta header with preamble, plus the data set with its pixel data).
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
      throw InputError(where, fname(file) + " is truncated (" + format_number(have) + " bytes; its header declares " +
                                  format_number(declared) + ")");
  }
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

std::string series_list_text(const ScannedFolder& f) {
  std::string s;
  for (const auto& [uid, files] : f.series) s += (s.empty() ? "" : ", ") + uid + " (" + std::to_string(files.size()) + " files)";
  return s;
}

// Resolves "DIR" or "DIR/UID" into a folder and the chosen series files.
struct DicomChoice {
  fs::path dir;
  std::string uid;
  std::vector<std::string> files;
};

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

template <class TImage>
typename TImage::Pointer read_dicom_series(const DicomChoice& c, const ScannedFolder& f, const VolumeReadOptions& opts) {
  const std::vector<std::string> files = sorted_checked_series(c.dir, f, c.files, opts);
  auto io = itk::GDCMImageIO::New();
  auto reader = itk::ImageSeriesReader<TImage>::New();
  reader->SetImageIO(io);
  reader->SetFileNames(files);
  try {
    reader->Update();
  } catch (const itk::ExceptionObject& e) {
    throw InputError(c.dir.string(), "cannot read DICOM series " + c.uid + ": " + itk_message(e));
  }
  typename TImage::Pointer out = reader->GetOutput();
  std::string position;  // PatientPosition of the (last read) slice: one value per series
  if (io->GetValueFromTag("0018|5100", position)) set_patient_position(out.GetPointer(), trim(position.c_str()));
  return out;
}

// ---------------------------------------------------------------------------------------------
// Files

// A NRRD header with per-axis "spacings" and a "space" field is not valid NRRD and teem (ITK's
// NrrdIO) refuses it, yet such headers exist (VTK's headsq quarter.nhdr: "space: 3D-left-handed",
// "spacings: 3.2 3.2 1.5", detached slices). The header is copied to a temporary file without its
// "space" line (so the spacings are valid, with an identity direction) and with the data file path
// made absolute, and that copy is read by ITK. Returns false when the header is not of this kind.
bool sanitized_nrrd_header(const fs::path& p, fs::path& out) {
  std::ifstream in(p, std::ios::binary);
  if (!in) return false;
  std::string line, text;
  bool has_space = false, has_spacings = false;
  std::vector<std::string> lines;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) break;  // end of the header (attached data follows)
    lines.push_back(line);
    if (lines.size() > 200) return false;
  }
  if (lines.empty() || lines[0].rfind("NRRD", 0) != 0) return false;
  for (const auto& l : lines) {
    if (l.rfind("space:", 0) == 0) has_space = true;
    if (l.rfind("spacings:", 0) == 0) has_spacings = true;
  }
  if (!(has_space && has_spacings)) return false;
  const fs::path dir = fs::absolute(p).parent_path();
  for (const auto& l : lines) {
    if (l.rfind("space:", 0) == 0) continue;
    if (l.rfind("data file:", 0) == 0 || l.rfind("datafile:", 0) == 0) {
      std::string v = l.substr(l.find(':') + 1);
      while (!v.empty() && v.front() == ' ') v.erase(v.begin());
      if (v.rfind("LIST", 0) == 0) return false;
      if (!v.empty() && v.front() != '/') v = (dir / v).string();
      text += "data file: " + v + "\n";
      continue;
    }
    text += l + "\n";
  }
  if (text.find("data file:") == std::string::npos) return false;  // attached data: cannot be split off
  out = temp_sibling(fs::temp_directory_path() / "colonflat_header.nhdr");
  std::ofstream o(out, std::ios::binary);
  o << text;
  return bool(o);
}

template <class TImage>
typename TImage::Pointer read_image_file(const fs::path& p) {
  const std::string where = p.string();
  auto io = io_for(p, false);
  if (!io) throw InputError(where, "unknown volume format (expected " + std::string(kReadFormats) + ")");
  if (!io->CanReadFile(p.c_str()))
    throw InputError(where, std::string("not a readable ") + io->GetNameOfClass() + " file");
  io->SetFileName(p.string());
  try {
    io->ReadImageInformation();
  } catch (const itk::ExceptionObject& e) {
    fs::path fixed;
    if (dynamic_cast<itk::NrrdImageIO*>(io.GetPointer()) && sanitized_nrrd_header(p, fixed)) {
      struct Remove {
        fs::path f;
        ~Remove() {
          std::error_code ec;
          fs::remove(f, ec);
        }
      } remove{fixed};
      try {
        return read_image_file<TImage>(fixed);
      } catch (const InputError&) {
      }
    }
    throw InputError(where, itk_message(e));
  }
  if (io->GetNumberOfDimensions() < 2 || io->GetNumberOfDimensions() > 3)
    throw InputError(where, "not a 3D volume (" + std::to_string(io->GetNumberOfDimensions()) + " dimensions)");
  if (io->GetNumberOfComponents() != 1)
    throw InputError(where, "not a scalar volume (" + std::to_string(io->GetNumberOfComponents()) +
                                " components per voxel)");
  if (auto* g = dynamic_cast<itk::GDCMImageIO*>(io.GetPointer())) {
    std::string sop, frames;
    g->GetValueFromTag("0008|0016", sop);
    g->GetValueFromTag("0028|0008", frames);
    sop = trim(sop.c_str());
    if (sop == kEnhancedCtSop || std::atoi(frames.c_str()) > 1)
      throw InputError(where, "enhanced multi-frame CT (" + (frames.empty() ? std::string("several") : trim(frames.c_str())) +
                                  " frames) is not supported; export a classic single-frame CT series");
  }
  auto reader = itk::ImageFileReader<TImage>::New();
  reader->SetImageIO(io);
  reader->SetFileName(p.string());
  try {
    reader->Update();
  } catch (const itk::ExceptionObject& e) {
    throw InputError(where, itk_message(e));
  }
  return reader->GetOutput();
}

template <class TImage>
typename TImage::Pointer read_any(const fs::path& p, const VolumeReadOptions& opts) {
  quiet_libraries();
  fs::path dir;
  std::string uid;
  if (split_series_path(p, dir, uid)) {
    auto f = scan_folder(dir);
    if (!f->series.count(uid)) throw InputError(p.string(), "no such file, and no DICOM series " + uid + " in " + dir.string());
    return read_dicom_series<TImage>(choose_series(dir, uid, opts, *f), *f, opts);
  }
  if (!fs::exists(p)) throw InputError(p.string(), "no such file");
  if (fs::is_directory(p)) {
    auto f = scan_folder(p);
    return read_dicom_series<TImage>(choose_series(p, "", opts, *f), *f, opts);
  }
  return read_image_file<TImage>(p);
}

void check_geometry(const itk::ImageBase<3>* img, const std::string& where) {
  for (int d = 0; d < 3; ++d) {
    const double s = img->GetSpacing()[d];
    if (!std::isfinite(s) || s <= 0) throw InputError(where, "invalid voxel spacing " + format_number(s));
    if (!std::isfinite(img->GetOrigin()[d])) throw InputError(where, "invalid origin");
  }
}

// Writes `img` to `tmp` in the format named by `target`'s extension.
template <class TImage>
void write_image_file(const TImage* img, const fs::path& tmp, const fs::path& target) {
  quiet_libraries();
  const std::string ext = full_ext(target);
  auto io = io_for(target, true);
  if (!io) throw UsageError(target.string() + ": cannot write this format (use " + kWriteFormats + ")");
  if (ext == ".mhd" || ext == ".nhdr")
    throw UsageError(target.string() + ": detached-header output is not supported (use " + kWriteFormats + ")");
  // The temporary must carry the full extension (".nii.gz"), else the IO would refuse it.
  fs::path w = tmp;
  const std::string tname = lower(tmp.filename().string());
  const bool ok_ext = tname.size() >= ext.size() && tname.compare(tname.size() - ext.size(), ext.size(), ext) == 0;
  if (!ok_ext) w = tmp.parent_path() / (tmp.filename().string() + ext);
  auto writer = itk::ImageFileWriter<TImage>::New();
  writer->SetImageIO(io);
  writer->SetFileName(w.string());
  writer->SetInput(img);
  writer->SetUseCompression(true);
  io->SetCompressionLevel(2);  // fast: noisy CT compresses little better at higher levels
  try {
    writer->Update();
  } catch (const itk::ExceptionObject& e) {
    std::error_code ec;
    fs::remove(w, ec);
    throw Error(target.string() + ": cannot write: " + itk_message(e));
  }
  if (w != tmp) {
    std::error_code ec;
    fs::rename(w, tmp, ec);
    if (ec) throw Error(target.string() + ": cannot write: " + ec.message());
  }
}

ShortImage::Pointer to_short(const CtImage* img) {
  auto out = ShortImage::New();
  out->CopyInformation(img);
  set_patient_position(out.GetPointer(), patient_position(img));  // the only metadata carried along
  out->SetRegions(img->GetLargestPossibleRegion());
  out->Allocate();
  const float* src = img->GetBufferPointer();
  std::int16_t* dst = out->GetBufferPointer();
  const std::size_t n = img->GetLargestPossibleRegion().GetNumberOfPixels();
  for (std::size_t i = 0; i < n; ++i) {
    const float v = src[i];
    const float c = std::isnan(v) ? 0.f : std::clamp(std::nearbyint(v), -32768.f, 32767.f);
    dst[i] = static_cast<std::int16_t>(c);
  }
  return out;
}

void write_ct_file(const CtImage* img, const fs::path& tmp, const fs::path& target) {
  if (!img) throw Error(target.string() + ": no volume to write");
  auto s = to_short(img);
  write_image_file<ShortImage>(s.GetPointer(), tmp, target);
}

void write_mask_file(const MaskImage* m, const fs::path& tmp, const fs::path& target) {
  if (!m) throw Error(target.string() + ": no mask to write");
  write_image_file<MaskImage>(m, tmp, target);
}

std::string fmt(double v, int prec = 6) {
  std::ostringstream s;
  s.imbue(std::locale::classic());
  s << std::setprecision(prec) << v;
  return s.str();
}

// FNV-1a 64 over a string.
std::uint64_t hash64(const std::string& s, std::uint64_t h = 1469598103934665603ull) {
  for (unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

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

std::string patient_position(const itk::ImageBase<3>* image) {
  std::string v;
  if (!image || !itk::ExposeMetaData<std::string>(image->GetMetaDataDictionary(), "0018|5100", v)) return "";
  v.erase(std::remove_if(v.begin(), v.end(), [](unsigned char c) { return std::isspace(c) || c == 0; }), v.end());
  std::transform(v.begin(), v.end(), v.begin(), [](unsigned char c) { return char(std::toupper(c)); });
  return v;
}

void set_patient_position(itk::ImageBase<3>* image, const std::string& position) {
  if (!image) return;
  auto& d = image->GetMetaDataDictionary();
  if (position.empty()) {
    if (d.HasKey("0018|5100")) d.Erase("0018|5100");
    return;
  }
  itk::EncapsulateMetaData<std::string>(d, "0018|5100", position);
}

CtImage::Pointer read_ct_volume(const fs::path& p, const VolumeReadOptions& opts) {
  auto img = read_any<CtImage>(p, opts);
  check_geometry(img, p.string());
  return img;
}

MaskImage::Pointer read_mask(const fs::path& p) {
  auto f = read_any<FloatImage>(p, {});
  check_geometry(f, p.string());
  auto m = MaskImage::New();
  m->CopyInformation(f);
  m->SetRegions(f->GetLargestPossibleRegion());
  m->Allocate();
  const std::size_t n = f->GetLargestPossibleRegion().GetNumberOfPixels();
  const float* src = f->GetBufferPointer();
  unsigned char* dst = m->GetBufferPointer();
  for (std::size_t i = 0; i < n; ++i) dst[i] = src[i] != 0.f ? 1 : 0;
  return m;
}

void write_ct_volume(const CtImage* image, const fs::path& file) {
  write_atomically(file, [&](const fs::path& tmp) { write_ct_file(image, tmp, file); });
}

void write_mask(const MaskImage* mask, const fs::path& file) {
  write_atomically(file, [&](const fs::path& tmp) { write_mask_file(mask, tmp, file); });
}

std::string derived_uid(std::uint64_t seed, const std::string& purpose) {
  const std::uint64_t a = hash64(purpose, hash64(std::to_string(seed)));
  const std::uint64_t b = hash64(purpose + "#2", a);
  // "2.25." + a decimal integer (at most 64 characters in all).
  return "2.25." + std::to_string(a) + std::to_string(b % 100000000000ull);
}

void write_dicom_series(const CtImage* image, const fs::path& dir, const DicomWriteOptions& opt) {
  quiet_libraries();
  if (!image) throw Error(dir.string() + ": no volume to write");
  if (fs::exists(dir) && !(fs::is_directory(dir) && fs::is_empty(dir)))
    throw UsageError(dir.string() + ": DICOM output folder exists and is not empty");
  const auto sh = to_short(image);
  const auto size = image->GetLargestPossibleRegion().GetSize();
  const auto sp = image->GetSpacing();
  const auto dirm = image->GetDirection();
  const std::string study = opt.study_uid.empty() ? derived_uid(opt.uid_seed, "study") : opt.study_uid;
  const std::string series = opt.series_uid.empty() ? derived_uid(opt.uid_seed, "series") : opt.series_uid;
  const std::string frame = opt.frame_of_reference_uid.empty() ? derived_uid(opt.uid_seed, "frame") : opt.frame_of_reference_uid;

  const fs::path tmpdir = temp_sibling(dir.has_filename() ? dir : dir.parent_path());
  std::error_code ec;
  fs::create_directories(tmpdir, ec);
  if (ec) throw Error(dir.string() + ": cannot create folder: " + ec.message());
  struct Cleanup {
    fs::path p;
    bool keep = false;
    ~Cleanup() {
      std::error_code e;
      if (!keep) fs::remove_all(p, e);
    }
  } cleanup{tmpdir};

  using Slice = itk::Image<std::int16_t, 2>;
  auto io = itk::GDCMImageIO::New();
  io->KeepOriginalUIDOn();
  io->SetComponentType(itk::IOComponentEnum::SHORT);
  auto writer = itk::ImageSeriesWriter<ShortImage, Slice>::New();
  writer->SetInput(sh);
  writer->SetImageIO(io);
  std::vector<std::string> names;
  std::vector<std::unique_ptr<itk::MetaDataDictionary>> dicts;
  itk::ImageSeriesWriter<ShortImage, Slice>::DictionaryArrayType arr;
  const std::string iop = fmt(dirm[0][0], 10) + "\\" + fmt(dirm[1][0], 10) + "\\" + fmt(dirm[2][0], 10) + "\\" +
                          fmt(dirm[0][1], 10) + "\\" + fmt(dirm[1][1], 10) + "\\" + fmt(dirm[2][1], 10);
  for (unsigned k = 0; k < size[2]; ++k) {
    char nm[32];
    std::snprintf(nm, sizeof nm, "IM%05u.dcm", k + 1);
    names.push_back((tmpdir / nm).string());
    ShortImage::IndexType idx{{0, 0, static_cast<itk::IndexValueType>(k)}};
    ShortImage::PointType pt;
    image->TransformIndexToPhysicalPoint(idx, pt);
    auto d = std::make_unique<itk::MetaDataDictionary>();
    auto put = [&](const char* tag, const std::string& v) { itk::EncapsulateMetaData<std::string>(*d, tag, v); };
    put("0008|0016", kCtSop);
    put("0008|0018", derived_uid(opt.uid_seed, "instance-" + series + "-" + std::to_string(k)));
    put("0008|0008", "ORIGINAL\\PRIMARY\\AXIAL");
    put("0008|0060", "CT");
    put("0008|0070", "ColonFlat");
    put("0008|103e", opt.series_description);
    put("0010|0010", opt.patient_name);
    put("0010|0020", opt.patient_id);
    put("0020|000d", study);
    put("0020|000e", series);
    put("0020|0052", frame);
    put("0020|0010", "1");
    put("0020|0011", "1");
    put("0020|0013", std::to_string(k + 1));
    put("0020|0032", fmt(pt[0], 10) + "\\" + fmt(pt[1], 10) + "\\" + fmt(pt[2], 10));
    put("0020|0037", iop);
    put("0020|1041", fmt(pt[2], 10));
    put("0028|0030", fmt(sp[1], 10) + "\\" + fmt(sp[0], 10));
    put("0018|0050", fmt(sp[2], 10));
    put("0018|0088", fmt(sp[2], 10));
    put("0028|1052", "0");
    put("0028|1053", "1");
    put("0028|1054", "HU");
    const std::string position = opt.patient_position.empty() ? patient_position(image) : opt.patient_position;
    if (!position.empty()) put("0018|5100", position);
    arr.push_back(d.get());
    dicts.push_back(std::move(d));
  }
  writer->SetFileNames(names);
  writer->SetMetaDataDictionaryArray(&arr);
  try {
    writer->Update();
  } catch (const itk::ExceptionObject& e) {
    throw Error(dir.string() + ": cannot write DICOM series: " + itk_message(e));
  }
  if (fs::exists(dir)) fs::remove(dir, ec);  // empty folder
  fs::rename(tmpdir, dir, ec);
  if (ec) throw Error(dir.string() + ": cannot write: " + ec.message());
  cleanup.keep = true;
}

nlohmann::json volume_info_json(const fs::path& p, const VolumeReadOptions& opts) {
  quiet_libraries();
  nlohmann::json j = {{"file", p.string()}, {"kind", "volume"}};
  fs::path dir;
  std::string uid;
  const bool folder = fs::is_directory(p) || split_series_path(p, dir, uid);
  if (folder) {
    if (dir.empty()) dir = p;
    auto f = scan_folder(dir);
    nlohmann::json list = nlohmann::json::array();
    for (const auto& s : list_dicom_series(dir))
      list.push_back({{"uid", s.uid}, {"files", s.files}, {"modality", s.modality}, {"description", s.description}});
    j["format"] = "DICOM series";
    j["series"] = list;
    if (uid.empty()) uid = opts.series_uid;
    if (f->series.size() > 1 && uid.empty()) {
      j["note"] = "several series; choose one with --series UID (or the path DIR/UID)";
      return j;
    }
    if (f->series.empty()) throw InputError(p.string(), "folder holds no readable DICOM file");
    j["series_uid"] = uid.empty() ? f->series.begin()->first : uid;
  } else {
    j["format"] = full_ext(p).empty() ? "DICOM" : full_ext(p).substr(1);
    if (!fs::exists(p)) throw InputError(p.string(), "no such file");
  }
  VolumeReadOptions o = opts;
  o.series_uid = uid.empty() ? opts.series_uid : uid;
  auto img = read_ct_volume(folder ? (uid.empty() ? dir : dir / uid) : p, o);
  const auto sz = img->GetLargestPossibleRegion().GetSize();
  const auto sp = img->GetSpacing();
  const auto org = img->GetOrigin();
  const auto dm = img->GetDirection();
  j["size"] = {sz[0], sz[1], sz[2]};
  j["spacing_mm"] = {sp[0], sp[1], sp[2]};
  j["origin_lps_mm"] = {org[0], org[1], org[2]};
  j["direction"] = {{dm[0][0], dm[0][1], dm[0][2]}, {dm[1][0], dm[1][1], dm[1][2]}, {dm[2][0], dm[2][1], dm[2][2]}};
  j["extent_mm"] = {sp[0] * sz[0], sp[1] * sz[1], sp[2] * sz[2]};
  const std::size_t n = img->GetLargestPossibleRegion().GetNumberOfPixels();
  const float* b = img->GetBufferPointer();
  double lo = std::numeric_limits<double>::infinity(), hi = -lo, sum = 0;
  for (std::size_t i = 0; i < n; ++i) {
    lo = std::min<double>(lo, b[i]);
    hi = std::max<double>(hi, b[i]);
    sum += b[i];
  }
  j["voxels"] = n;
  j["hu_range"] = {lo, hi};
  j["hu_mean"] = n ? sum / double(n) : 0.0;
  j["units"] = "HU";
  j["coordinate_system"] = "LPS";
  if (n && lo >= 0) j["note"] = "no negative values: these may be raw scanner units (about HU + 1024), not HU";
  return j;
}

std::string volume_info_text(const nlohmann::json& j) {
  std::ostringstream s;
  auto v3 = [](const nlohmann::json& a) {
    std::ostringstream t;
    t << "[" << fmt(a[0].get<double>()) << ", " << fmt(a[1].get<double>()) << ", " << fmt(a[2].get<double>()) << "]";
    return t.str();
  };
  s << j["file"].get<std::string>() << "\nformat          " << j["format"].get<std::string>() << "\n";
  if (j.contains("series")) {
    s << "series          " << j["series"].size() << "\n";
    for (const auto& x : j["series"])
      s << "  " << x["uid"].get<std::string>() << "  " << x["files"] << " files  " << x["modality"].get<std::string>()
        << (x["description"].get<std::string>().empty() ? "" : "  " + x["description"].get<std::string>()) << "\n";
  }
  if (j.contains("size")) {
    s << "size            " << j["size"][0] << " x " << j["size"][1] << " x " << j["size"][2] << " voxels\n"
      << "spacing         " << v3(j["spacing_mm"]) << " mm\n"
      << "origin          " << v3(j["origin_lps_mm"]) << " mm (LPS)\n"
      << "direction       " << v3(j["direction"][0]) << " " << v3(j["direction"][1]) << " " << v3(j["direction"][2])
      << "\n"
      << "extent          " << v3(j["extent_mm"]) << " mm\n"
      << "HU range        " << fmt(j["hu_range"][0].get<double>()) << " .. " << fmt(j["hu_range"][1].get<double>())
      << " (mean " << fmt(j["hu_mean"].get<double>(), 5) << ")\n";
  }
  if (j.contains("note")) s << "note: " << j["note"].get<std::string>() << "\n";
  return s.str();
}

bool looks_like_volume(const fs::path& p) {
  const std::string e = full_ext(p);
  if (e == ".nrrd" || e == ".nhdr" || e == ".nii" || e == ".nii.gz" || e == ".mha" || e == ".mhd" || e == ".dcm" ||
      e == ".ima")
    return true;
  fs::path dir;
  std::string uid;
  if (split_series_path(p, dir, uid)) return true;
  std::error_code ec;
  if (fs::is_directory(p, ec)) return true;
  if (fs::is_regular_file(p, ec) && has_dicom_magic(p)) return true;
  return false;
}

bool try_volume_info(const std::string& path, bool json, std::ostream& out) {
  return try_volume_info(path, json, out, "");
}

bool try_volume_info(const std::string& path, bool json, std::ostream& out, const std::string& series_uid) {
  if (!looks_like_volume(path)) return false;
  VolumeReadOptions o;
  o.series_uid = series_uid;
  const nlohmann::json j = volume_info_json(path, o);
  if (json) out << j.dump(2) << "\n";
  else out << volume_info_text(j);
  return true;
}

const ArtifactType& volume_artifact() {
  static const ArtifactType t{
      "volume", "CT volume in HU (" + std::string(kReadFormats) + "), LPS mm",
      [](const fs::path& p) { return std::any(read_ct_volume(p)); },
      [](const std::any& v, const fs::path& tmp, const fs::path& target) {
        write_ct_file(std::any_cast<const CtImage::Pointer&>(v).GetPointer(), tmp, target);
      }};
  return t;
}

const ArtifactType& mask_artifact() {
  static const ArtifactType t{
      "mask", "binary mask, 1 = lumen (" + std::string(kWriteFormats) + "), LPS mm",
      [](const fs::path& p) { return std::any(read_mask(p)); },
      [](const std::any& v, const fs::path& tmp, const fs::path& target) {
        write_mask_file(std::any_cast<const MaskImage::Pointer&>(v).GetPointer(), tmp, target);
      }};
  return t;
}

}  // namespace cf
