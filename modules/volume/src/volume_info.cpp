// Volume info for `colonflat info` and the pipeline artifacts "volume" and "mask".
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

#include "volume_internal.h"

namespace cf {

using namespace vio;

namespace {
bool is_binary(const float* v, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i)
    if (v[i] != 0.f && v[i] != 1.f) return false;
  return true;
}
}  // namespace

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
  j["coordinate_system"] = "LPS";
  if (lo >= 0 && hi <= 1 && (hi == 1 || lo == 0) && is_binary(b, n)) {  // a mask (e.g. lumen_mask.nrrd)
    const double ones = sum;
    j["kind"] = "mask";
    j["mask_voxels"] = static_cast<std::size_t>(ones);
    j["mask_volume_ml"] = ones * sp[0] * sp[1] * sp[2] / 1000.0;
    return j;
  }
  j["hu_range"] = {lo, hi};
  j["hu_mean"] = n ? sum / double(n) : 0.0;
  j["units"] = "HU";
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
      << "extent          " << v3(j["extent_mm"]) << " mm\n";
    if (j.value("kind", "") == "mask")
      s << "mask            " << j["mask_voxels"] << " voxels = 1, " << fmt(j["mask_volume_ml"].get<double>(), 5)
        << " mL (binary mask, e.g. a lumen mask)\n";
  }
  if (j.contains("hu_range")) {
    s << "HU range        " << fmt(j["hu_range"][0].get<double>()) << " .. " << fmt(j["hu_range"][1].get<double>())
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
        if (const auto* c = std::any_cast<CompactCtImage::Pointer>(&v))  // the stand-in: the same file
          return write_ct_file(expand_ct(**c).GetPointer(), tmp, target);
        write_ct_file(std::any_cast<const CtImage::Pointer&>(v).GetPointer(), tmp, target);
      },
      {".nrrd", ".nii", ".nii.gz", ".mha"},
      [](const std::any& v) -> std::optional<std::any> {
        CompactCtImage::Pointer c = compact_ct(*std::any_cast<const CtImage::Pointer&>(v));
        if (!c) return std::nullopt;
        return std::any(c);
      },
      [](const std::any& v) { return std::any(expand_ct(*std::any_cast<const CompactCtImage::Pointer&>(v))); }};
  return t;
}

const ArtifactType& mask_artifact() {
  static const ArtifactType t{
      "mask", "binary mask, 1 = lumen (" + std::string(kWriteFormats) + "), LPS mm",
      [](const fs::path& p) { return std::any(read_mask(p)); },
      [](const std::any& v, const fs::path& tmp, const fs::path& target) {
        if (const auto* c = std::any_cast<std::shared_ptr<const CompactMask>>(&v))  // the stand-in: the same file
          return write_mask_file(expand_mask(**c).GetPointer(), tmp, target);
        write_mask_file(std::any_cast<const MaskImage::Pointer&>(v).GetPointer(), tmp, target);
      },
      {".nrrd", ".nii", ".nii.gz", ".mha"},
      [](const std::any& v) -> std::optional<std::any> {
        std::shared_ptr<const CompactMask> c = compact_mask(*std::any_cast<const MaskImage::Pointer&>(v));
        if (!c) return std::nullopt;
        return std::any(c);
      },
      [](const std::any& v) {
        return std::any(expand_mask(*std::any_cast<const std::shared_ptr<const CompactMask>&>(v)));
      }};
  return t;
}

}  // namespace cf

