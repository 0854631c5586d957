// Checks on what a volume file declares and holds: declared sizes against the data actually in
// the file(s) and against the memory budget (before ITK allocates anything), non-finite voxels,
// and whether a volume is a mask at all.
#include <itkImageIOBase.h>

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

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

}  // namespace

void check_declared_volume(const fs::path& p, const itk::ImageIOBase& io) {
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
