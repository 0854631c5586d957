// Writing volumes (NRRD, NIfTI, MetaImage; int16 HU or uint8 masks) and DICOM CT series.
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
#include "colonflat/core/write_errors.h"
#include "colonflat/core/error.h"

#include "volume_internal.h"

namespace cf {
namespace vio {
namespace {

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
    const std::string full = file_system_problem(w);  // before the cut file goes: ITK's words name no cause
    std::error_code ec;
    fs::remove(w, ec);
    throw Error(target.string() + ": cannot write: " + (full.empty() ? itk_message(e) : full));
  }
  if (w != tmp) {
    std::error_code ec;
    fs::rename(w, tmp, ec);
    if (ec) throw Error(target.string() + ": cannot write: " + ec.message());
  }
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

}  // namespace vio

using namespace vio;

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

// The DICOM tags of slice k (0-based) at patient position `pt` (LPS mm).
std::unique_ptr<itk::MetaDataDictionary> slice_dictionary(const DicomWriteOptions& opt, unsigned k, const double pt[3],
                                                          const std::string& study, const std::string& series,
                                                          const std::string& frame, const std::string& iop,
                                                          const CtImage::SpacingType& sp) {
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
  return d;
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
    const double position[3] = {pt[0], pt[1], pt[2]};
    auto d = slice_dictionary(opt, k, position, study, series, frame, iop, sp);
    const std::string patient_pos = opt.patient_position.empty() ? patient_position(image) : opt.patient_position;
    if (!patient_pos.empty()) itk::EncapsulateMetaData<std::string>(*d, "0018|5100", patient_pos);
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

}  // namespace cf
