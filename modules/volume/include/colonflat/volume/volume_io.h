#pragma once
// CT volumes and lumen masks through ITK: DICOM series folders (GDCM), NRRD (attached and detached
// header), NIfTI, MetaImage. Everything is in LPS millimetres with ITK's origin/spacing/direction
// (DICOM patient space); CT values are Hounsfield units (DICOM rescale slope/intercept applied).
//
//   cf::CtImage::Pointer ct = cf::read_ct_volume("series_dir/");   // or "ct.nrrd", "ct.nii.gz", ...
//   cf::write_mask(mask, "lumen_mask.nrrd");                       // atomic
#include <itkImage.h>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colonflat/core/stage.h"

namespace cf {

using CtImage = itk::Image<float, 3>;            // HU, LPS mm geometry
using MaskImage = itk::Image<unsigned char, 3>;  // 0 outside, 1 lumen

struct VolumeReadOptions {
  // A DICOM folder holding several series: the SeriesInstanceUID to read (empty: the folder must
  // hold exactly one series). A path "DIR/UID" whose last part is a series UID in DIR also selects it.
  std::string series_uid;
  // DICOM slice positions: a gap differing from the median gap by more than this fraction is an
  // error (missing slice, uneven spacing).
  double slice_gap_tolerance = 0.1;
};

// One DICOM series in a folder.
struct DicomSeriesInfo {
  std::string uid;          // SeriesInstanceUID
  std::size_t files = 0;    // number of files (slices)
  std::string modality;     // "CT", ...
  std::string description;  // SeriesDescription
};

// ITK's filters use cf::thread_count() threads from now on (core threads.h listener; called by
// colonflat_main, idempotent).
void itk_follows_thread_count();

// The series in a folder (empty if it holds no readable DICOM file).
std::vector<DicomSeriesInfo> list_dicom_series(const std::filesystem::path& dir);

// Reads a CT volume: a DICOM series folder, a single DICOM file, .nrrd/.nhdr, .nii/.nii.gz,
// .mha/.mhd. Throws InputError (missing or unreadable file, several series without a choice,
// missing slices or uneven slice spacing, enhanced multi-frame CT, non-scalar or non-3D data).
CtImage::Pointer read_ct_volume(const std::filesystem::path& file_or_dicom_dir, const VolumeReadOptions& = {});

// DICOM PatientPosition (0018,5100) carried with a volume: "HFS", "HFP", "FFS", "FFP", "HFDR",
// "HFDL", "FFDR", "FFDL" or "" when unknown. Read from DICOM series (first slice) and from the NRRD
// key "0018|5100"; written by write_ct_volume (NRRD, MetaImage) and write_dicom_series.
std::string patient_position(const itk::ImageBase<3>* image);
void set_patient_position(itk::ImageBase<3>* image, const std::string& position);

// Reads a mask (any voxel type; non-zero = 1). Throws InputError.
MaskImage::Pointer read_mask(const std::filesystem::path& file);

// Writes a CT volume as int16 HU (values rounded and clamped), compressed where the format allows.
// Formats by extension: .nrrd, .nii, .nii.gz, .mha. Atomic (temporary file, then rename).
void write_ct_volume(const CtImage* image, const std::filesystem::path& file);
// Writes a mask as uint8 (0/1), compressed; same formats; atomic.
void write_mask(const MaskImage* mask, const std::filesystem::path& file);

// A CT volume as a classic single-frame DICOM CT series (one file per slice, int16 HU, rescale
// slope 1 / intercept 0), readable by ITK/GDCM and other DICOM readers. UIDs given here are used
// as is; empty ones are derived from `uid_seed` (deterministic output for a given seed).
struct DicomWriteOptions {
  std::string study_uid, series_uid, frame_of_reference_uid;
  std::uint64_t uid_seed = 1;
  std::string patient_name = "PHANTOM^COLONFLAT";
  std::string patient_id = "CF-PHANTOM";
  std::string series_description = "ColonFlat synthetic CT colonography";
  std::string patient_position;  // DICOM PatientPosition (0018,5100); empty: the image's own (patient_position())
};
// Writes `dir` atomically (a temporary sibling folder renamed at the end); `dir` must not exist or
// be empty.
void write_dicom_series(const CtImage* image, const std::filesystem::path& dir, const DicomWriteOptions& = {});

// A deterministic DICOM UID ("2.25.<decimal>") from a seed and a purpose string.
std::string derived_uid(std::uint64_t seed, const std::string& purpose);

// Size, spacing, origin, direction, HU range (and DICOM series) of a volume, as JSON.
nlohmann::json volume_info_json(const std::filesystem::path& file_or_dicom_dir, const VolumeReadOptions& = {});
// The same, as text lines.
std::string volume_info_text(const nlohmann::json& info);

// True when `path` names a volume (volume extension, DICOM file, folder of DICOM files, or
// DIR/SERIES_UID).
bool looks_like_volume(const std::filesystem::path& path);

// For `colonflat info`: when `path` is a volume, prints its info (text or JSON) to `out` and returns
// true; returns false (printing nothing) when it is not a volume. Throws InputError when it is a
// volume that cannot be read.
bool try_volume_info(const std::string& path, bool json, std::ostream& out);
// The same with a DICOM series chosen by UID (for `colonflat info DIR --series UID`).
bool try_volume_info(const std::string& path, bool json, std::ostream& out, const std::string& series_uid);

// A CT held in 16 bits: HU of CT scanners are integers in [-32768, 32767] (DICOM and NRRD store
// them as 16-bit integers), so a CtImage (float) whose voxels all are such integers is held
// exactly in half the memory. compact_ct: that image (geometry and header dictionary kept), or
// null when a voxel is not such an integer (e.g. a resampled or filtered CT). expand_ct: the float
// image back, equal voxel for voxel, with the same geometry and dictionary.
using CompactCtImage = itk::Image<short, 3>;
CompactCtImage::Pointer compact_ct(const CtImage& ct);
CtImage::Pointer expand_ct(const CompactCtImage& compact);

// A lumen mask held in one bit per voxel: every voxel 0 or 1 (a mask as segment and the readers
// give it), 64 voxels a word in buffer order (voxel i: bit i % 64 of word i / 64). `grid`: an image
// with the mask's geometry (region, origin, spacing, direction) and header dictionary, no pixels.
// compact_mask: null when a voxel is neither 0 nor 1. expand_mask: the mask back, equal voxel for
// voxel, with the same geometry and dictionary.
struct CompactMask {
  MaskImage::Pointer grid;
  std::vector<std::uint64_t> bits;
};
std::shared_ptr<const CompactMask> compact_mask(const MaskImage& mask);
MaskImage::Pointer expand_mask(const CompactMask& compact);

// Pipeline artifacts: "volume" (std::any holding CtImage::Pointer; compactable to a
// CompactCtImage::Pointer by compact_ct) and "mask" (MaskImage::Pointer; compactable to a
// std::shared_ptr<const CompactMask> by compact_mask).
const ArtifactType& volume_artifact();
const ArtifactType& mask_artifact();

}  // namespace cf
