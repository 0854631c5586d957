// Checks on what a volume file declares and holds: declared sizes against the data actually in
// the file(s) and against the memory budget (before ITK allocates anything), non-finite voxels,
// and whether a volume is a mask at all.
#include <itkImageIOBase.h>
#include <zlib.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>
#include <vector>

#include "colonflat/core/error.h"
#include "colonflat/core/memory_budget.h"
#include "colonflat/core/params.h"
#include "volume_internal.h"

namespace cf {
namespace vio {
namespace {

// The header text of a NRRD/MetaImage file (up to the first blank line or 64 KiB).
std::string header_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::string text, line;
  while (text.size() < (1u << 16) && std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) break;
    text += line + "\n";
  }
  return text;
}

// The value of "key: v" (NRRD) or "Key = v" (MetaImage) in a header, trimmed; "" when absent.
std::string header_value(const std::string& text, const std::string& key, char sep) {
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    const auto at = line.find(sep);
    if (at == std::string::npos) continue;
    std::string k = lower(line.substr(0, at)), v = line.substr(at + 1);
    while (!k.empty() && k.back() == ' ') k.pop_back();
    if (k != key) continue;
    const auto b = v.find_first_not_of(" ="), e = v.find_last_not_of(' ');
    return b == std::string::npos ? "" : v.substr(b, e - b + 1);
  }
  return "";
}

// Where the voxel data lie and the most it can have been compressed (1 = raw; 0 = unknown).
struct DataSource {
  fs::path file;
  double max_ratio = 1.0;
};

// zlib cannot compress better than about 1032:1.
constexpr double kGzipRatio = 1100.0;

DataSource nrrd_source(const fs::path& p) {
  const std::string h = header_text(p);
  std::string enc = lower(header_value(h, "encoding", ':'));
  std::string data = header_value(h, "data file", ':');
  if (data.empty()) data = header_value(h, "datafile", ':');
  DataSource s{p, 1.0};
  if (enc == "gzip" || enc == "gz") s.max_ratio = kGzipRatio;
  else if (enc != "raw" && enc != "ascii" && enc != "text" && enc != "txt" && enc != "hex") s.max_ratio = 0;
  if (!data.empty()) {
    if (data.find(' ') != std::string::npos || data.find('%') != std::string::npos) s.max_ratio = 0;  // LIST / pattern
    else s.file = fs::path(data).is_absolute() ? fs::path(data) : p.parent_path() / data;
  }
  return s;
}

DataSource meta_source(const fs::path& p) {
  const std::string h = header_text(p);
  const std::string data = header_value(h, "elementdatafile", '=');
  DataSource s{p, lower(header_value(h, "compresseddata", '=')) == "true" ? kGzipRatio : 1.0};
  if (data.empty() || data.find(' ') != std::string::npos || data.find('%') != std::string::npos) s.max_ratio = 0;
  else if (data != "LOCAL") s.file = fs::path(data).is_absolute() ? fs::path(data) : p.parent_path() / data;
  return s;
}

DataSource data_source(const fs::path& p) {
  const std::string e = full_ext(p);
  if (e == ".nrrd" || e == ".nhdr") return nrrd_source(p);
  if (e == ".mha" || e == ".mhd") return meta_source(p);
  if (e == ".nii") return {p, 1.0};
  if (e == ".nii.gz") return {p, kGzipRatio};
  return {p, 0.0};  // DICOM file: transfer syntax decides; GDCM checks its own lengths
}

// A single-file NIfTI carries "n+1\0" at byte 344 (NIfTI-1) or "n+2\0" at byte 4 (NIfTI-2);
// without it the NIfTI library falls back to reading the header as ANALYZE 7.5, which a .nii is not.
void check_nifti_magic(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  char head[348] = {};
  in.read(head, sizeof head);
  const bool nifti1 = in.gcount() == 348 && std::memcmp(head + 344, "n+1\0", 4) == 0;
  const bool nifti2 = in.gcount() >= 8 && std::memcmp(head + 4, "n+2\0", 4) == 0;
  if (!nifti1 && !nifti2) throw InputError(p.string(), "not a NIfTI file: no 'n+1' or 'n+2' magic (corrupt header?)");
}

// A gzip file must decompress to its end without error and hold at least `needed` bytes: the
// NIfTI library zero-fills a truncated .nii.gz silently. Streams through zlib, 64 KiB at a time.
void check_gzip_complete(const fs::path& p, double needed, const std::string& what) {
  gzFile gz = gzopen(p.c_str(), "rb");
  if (!gz) throw InputError(p.string(), "cannot open for reading");
  std::vector<char> buf(1 << 16);
  double total = 0;
  int n = 0;
  while ((n = gzread(gz, buf.data(), static_cast<unsigned>(buf.size()))) > 0) total += n;
  int code = Z_OK;
  const std::string why = n < 0 ? gzerror(gz, &code) : "";
  gzclose(gz);
  if (n < 0) throw InputError(p.string(), "corrupt or truncated gzip data (" + why + ")");
  // The trailer's ISIZE (last 4 bytes) is the decompressed length mod 2^32: a file cut inside its
  // trailer still decompresses, but this no longer matches.
  std::ifstream tail(p, std::ios::binary | std::ios::ate);
  unsigned char isize[4] = {};
  if (tail.tellg() >= 4) {
    tail.seekg(-4, std::ios::end);
    tail.read(reinterpret_cast<char*>(isize), 4);
  }
  const std::uint32_t declared = isize[0] | (isize[1] << 8) | (isize[2] << 16) | (std::uint32_t(isize[3]) << 24);
  if (declared != static_cast<std::uint32_t>(static_cast<std::uint64_t>(total)))
    throw InputError(p.string(), "truncated gzip file (its trailer does not match the data)");
  if (total < needed)
    throw InputError(p.string(), what + " declares " + human_bytes(needed) + " of data but the file decompresses to " +
                                     human_bytes(total) + " (truncated file or wrong header)");
}

}  // namespace

void check_declared_volume(const fs::path& p, const itk::ImageIOBase& io) {
  if (full_ext(p) == ".nii") check_nifti_magic(p);
  if (io.GetComponentType() == itk::IOComponentEnum::UNKNOWNCOMPONENTTYPE)
    throw InputError(p.string(), "unknown voxel type in the header (corrupt header?)");
  double voxels = 1;
  std::string dims;
  for (unsigned d = 0; d < io.GetNumberOfDimensions(); ++d) {
    voxels *= double(io.GetDimensions(d));
    dims += (dims.empty() ? "" : " x ") + std::to_string(io.GetDimensions(d));
  }
  const double stored = voxels * double(io.GetComponentSize()) * double(io.GetNumberOfComponents());
  const std::string what = "the header (" + dims + " voxels of " +
                           itk::ImageIOBase::GetComponentTypeAsString(io.GetComponentType()) + ")";
  const DataSource src = data_source(p);
  if (src.max_ratio > 0) {
    std::error_code ec;
    if (!fs::exists(src.file, ec)) throw InputError(p.string(), "its data file " + src.file.string() + " does not exist");
    check_declared_data(src.file, what, stored / src.max_ratio);
  }
  // The file's voxels as read, plus the float copy every reader makes.
  check_memory_budget(p.string(), what, stored + voxels * double(sizeof(float)));
  if (full_ext(p) == ".nii.gz") check_gzip_complete(p, stored + 348.0, what);
}

void check_finite_voxels(const FloatImage* img, const std::string& where) {
  const std::size_t n = img->GetLargestPossibleRegion().GetNumberOfPixels();
  const float* v = img->GetBufferPointer();
  std::size_t bad = 0, first = n;
  for (std::size_t i = 0; i < n; ++i)
    if (!std::isfinite(v[i])) {
      if (!bad) first = i;
      ++bad;
    }
  if (!bad) return;
  const auto size = img->GetLargestPossibleRegion().GetSize();
  std::ostringstream s;
  s << bad << " of " << n << " voxels are NaN or infinite (first at voxel (" << first % size[0] << ", "
    << (first / size[0]) % size[1] << ", " << first / (size[0] * size[1]) << "))";
  throw InputError(where, s.str());
}

void check_mask_values(const FloatImage* img, const std::string& where) {
  const std::size_t n = img->GetLargestPossibleRegion().GetNumberOfPixels();
  const float* v = img->GetBufferPointer();
  float lo = 0, hi = 0;
  std::set<float> labels;
  bool integral = true;
  for (std::size_t i = 0; i < n; ++i) {
    lo = std::min(lo, v[i]);
    hi = std::max(hi, v[i]);
    if (v[i] != std::floor(v[i])) integral = false;
    if (labels.size() <= 64) labels.insert(v[i]);
  }
  if (integral && lo >= 0 && hi <= 255 && labels.size() <= 64) return;
  throw InputError(where, "not a mask: values must be 0 and 1 (or a few integer labels, non-zero = lumen), found " +
                              format_number(lo) + " .. " + format_number(hi) +
                              (labels.size() > 64 ? " with more than 64 distinct values" : "") +
                              (lo < -100 ? " (a CT volume in HU?)" : ""));
}

}  // namespace vio
}  // namespace cf
