#pragma once
// Internal to the volume module: helpers shared by its source files (reading files, DICOM
// folders, writing, info). Not installed; include only from modules/volume/src.
#include <gdcmScanner.h>
#include <itkImageIOBase.h>

#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "colonflat/volume/volume_io.h"

namespace cf {
namespace vio {

namespace fs = std::filesystem;
using ShortImage = itk::Image<std::int16_t, 3>;
using FloatImage = itk::Image<float, 3>;

extern const char* const kEnhancedCtSop;
extern const char* const kCtSop;
extern const char* const kReadFormats;
extern const char* const kWriteFormats;

void quiet_libraries();
std::string lower(std::string s);
std::string full_ext(const fs::path& p);           // ".nii.gz" or the last extension, lower case
std::string itk_message(const itk::ExceptionObject& e);
std::string trim(const char* v);
std::vector<double> ds_values(const std::string& s);
bool has_dicom_magic(const fs::path& p);
itk::ImageIOBase::Pointer io_for(const fs::path& p, bool for_writing);
std::string fmt(double v, int prec = 6);

// DICOM folders (dicom_read.cpp).
struct ScannedFolder {
  std::map<std::string, std::vector<std::string>> series;  // uid -> files
  gdcm::Scanner scanner;
};
struct DicomChoice {
  fs::path dir;
  std::string uid;
  std::vector<std::string> files;
};
std::unique_ptr<ScannedFolder> scan_folder(const fs::path& dir);
// "DIR/UID" where DIR exists and UID looks like a DICOM UID.
bool split_series_path(const fs::path& p, fs::path& dir, std::string& uid);
DicomChoice choose_series(const fs::path& dir, std::string uid, const VolumeReadOptions& opts, const ScannedFolder& f);
// Throws InputError(where, "<file> is truncated ...") when an uncompressed DICOM file is shorter
// than its data set declares; `ts` is its transfer syntax UID.
void check_dicom_length(const fs::path& file, const std::string& where, const std::string& ts);
std::string dicom_transfer_syntax(const fs::path& file);
// False when a DICOM Part-10 file lacks its preamble/magic or is cut inside its meta header
// (GDCM would abort on it).
bool dicom_meta_complete(const fs::path& file);
FloatImage::Pointer read_dicom_series(const DicomChoice& c, const ScannedFolder& f, const VolumeReadOptions& opts);

// Files (volume_read.cpp): any readable volume as float voxels, sizes checked before allocation.
FloatImage::Pointer read_any(const fs::path& p, const VolumeReadOptions& opts);

// Checks (volume_checks.cpp). Each throws InputError naming `where` / `p` with the numbers.
// Declared size vs the data in the file(s) and the memory budget; call before reading voxels.
void check_declared_volume(const fs::path& p, const itk::ImageIOBase& io);
// No NaN or infinite voxel.
void check_finite_voxels(const FloatImage* img, const std::string& where);
// Values 0/1 or a few non-negative integer labels (refuses a CT given as a mask).
void check_mask_values(const FloatImage* img, const std::string& where);

// Writing (volume_write.cpp): `img` to `tmp` in the format of `target`'s extension.
void write_ct_file(const CtImage* img, const fs::path& tmp, const fs::path& target);
void write_mask_file(const MaskImage* m, const fs::path& tmp, const fs::path& target);
ShortImage::Pointer to_short(const CtImage* img);

}  // namespace vio
}  // namespace cf
