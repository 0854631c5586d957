// Reading volume files (NRRD, NIfTI, MetaImage, single DICOM files) and DICOM series as float
// voxels: declared sizes are checked against the file and the memory budget before allocation.
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

#include "colonflat/core/library_output.h"
#include "colonflat/core/malloc_tunables.h"
#include "colonflat/core/threads.h"
#include "volume_internal.h"

namespace cf {
namespace vio {
namespace {

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

// The file `p` read by `io` as an Image (ITK converts the stored voxels); InputError naming the file.
template <class Image>
typename Image::Pointer read_through(itk::ImageIOBase* io, const fs::path& p) {
  auto reader = itk::ImageFileReader<Image>::New();
  reader->SetImageIO(io);
  reader->SetFileName(p.string());
  try {
    reader->Update();
  } catch (const itk::ExceptionObject& e) {
    throw InputError(p.string(), itk_message(e));
  }
  return reader->GetOutput();
}

// A NRRD or MetaImage file of 16-bit voxels (how CT is stored): formats without a rescale of
// their own, so the float image is the stored value, as ITK's conversion gives it.
bool stored_as_short(const itk::ImageIOBase& io) {
  const bool plain = dynamic_cast<const itk::NrrdImageIO*>(&io) || dynamic_cast<const itk::MetaImageIO*>(&io);
  return plain && io.GetComponentType() == itk::IOComponentEnum::SHORT && io.GetNumberOfComponents() == 1;
}

// Reads such a file as stored and converts it to float on the threads, each first touching its
// share of the float image: ITK's own conversion is one serial loop (0.6 s of the real CT's read,
// 512 x 512 x 430 voxels). The same voxels, geometry and header dictionary as ITK's float read.
FloatImage::Pointer read_short_as_float(itk::ImageIOBase* io, const fs::path& p) {
  using ShortImage = itk::Image<short, 3>;
  const ShortImage::Pointer in = read_through<ShortImage>(io, p);
  auto out = FloatImage::New();
  out->CopyInformation(in);
  out->SetRegions(in->GetLargestPossibleRegion());
  out->SetMetaDataDictionary(in->GetMetaDataDictionary());
  out->Allocate();  // every voxel is written below
  const short* src = in->GetBufferPointer();
  float* dst = out->GetBufferPointer();
  parallel_for(in->GetLargestPossibleRegion().GetNumberOfPixels(), [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) dst[i] = static_cast<float>(src[i]);
  });
  return out;
}

FloatImage::Pointer read_image_file(const fs::path& p) {
  const std::string where = p.string();
  auto io = io_for(p, false);
  if (!io) throw InputError(where, "unknown volume format (expected " + std::string(kReadFormats) + ")");
  if (dynamic_cast<itk::GDCMImageIO*>(io.GetPointer()) && !dicom_meta_complete(p))
    throw InputError(where, "not a complete DICOM file (no 'DICM' preamble, or cut inside its meta header)");
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
        return read_image_file(fixed);
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
  check_declared_volume(p, *io);
  if (dynamic_cast<itk::GDCMImageIO*>(io.GetPointer())) check_dicom_length(p, where, dicom_transfer_syntax(p));
  if (stored_as_short(*io)) return read_short_as_float(io, p);
  return read_through<FloatImage>(io, p);
}


void check_geometry(const itk::ImageBase<3>* img, const std::string& where) {
  for (int d = 0; d < 3; ++d) {
    const double s = img->GetSpacing()[d];
    if (!std::isfinite(s) || s <= 0) throw InputError(where, "invalid voxel spacing " + format_number(s));
    if (!std::isfinite(img->GetOrigin()[d])) throw InputError(where, "invalid origin");
  }
}

FloatImage::Pointer read_any_uncaptured(const fs::path& p, const VolumeReadOptions& opts) {
  quiet_libraries();
  fs::path dir;
  std::string uid;
  if (split_series_path(p, dir, uid)) {
    auto f = scan_folder(dir);
    if (!f->series.count(uid)) throw InputError(p.string(), "no such file, and no DICOM series " + uid + " in " + dir.string());
    return read_dicom_series(choose_series(dir, uid, opts, *f), *f, opts);
  }
  if (!fs::exists(p)) throw InputError(p.string(), "no such file");
  if (fs::is_directory(p)) {
    auto f = scan_folder(p);
    return read_dicom_series(choose_series(p, "", opts, *f), *f, opts);
  }
  return read_image_file(p);
}


}  // namespace

// Reads with the libraries' own printing captured: it is folded into the error, and a read that
// "succeeded" while the library reported an error is refused.
FloatImage::Pointer read_any(const fs::path& p, const VolumeReadOptions& opts) {
  LibraryOutputCapture capture;
  FloatImage::Pointer img;
  try {
    img = read_any_uncaptured(p, opts);
  } catch (const InputError& e) {
    const std::string said = capture.text();
    if (said.empty()) throw;
    throw InputError(e.file(), e.problem() + " (library: " + said.substr(0, 160) + ")");
  }
  const std::string said = capture.text();
  if (said.find("rror") != std::string::npos || said.find("not read") != std::string::npos)
    throw InputError(p.string(), "the reader reported a problem: " + said.substr(0, 200));
  return img;
}

}  // namespace vio

using namespace vio;

// ITK reads a file whose voxels are not float into a buffer of the file's type and converts it:
// for a 16-bit CT that buffer is half the float image (457 MB at 512 x 512 x 873), freed into a
// heap our malloc settings never shrink (core/malloc_tunables.h), while segment's large buffers
// are mapped apart from the heap and cannot reuse it. So the reader's free memory goes back to
// the kernel as soon as the volume is read, not at the end of the stage that read it.
CtImage::Pointer read_ct_volume(const fs::path& p, const VolumeReadOptions& opts) {
  auto img = read_any(p, opts);
  release_free_memory();
  check_geometry(img, p.string());
  check_finite_voxels(img, p.string());
  return img;
}

MaskImage::Pointer read_mask(const fs::path& p) {
  auto f = read_any(p, {});
  check_geometry(f, p.string());
  check_mask_values(f, p.string());
  auto m = MaskImage::New();
  m->CopyInformation(f);
  m->SetRegions(f->GetLargestPossibleRegion());
  m->Allocate();
  const std::size_t n = f->GetLargestPossibleRegion().GetNumberOfPixels();
  const float* src = f->GetBufferPointer();
  unsigned char* dst = m->GetBufferPointer();
  for (std::size_t i = 0; i < n; ++i) dst[i] = src[i] != 0.f ? 1 : 0;
  f = nullptr;  // the float copy (4 bytes a voxel) goes back to the kernel, as read_ct_volume's buffer
  release_free_memory();
  return m;
}

}  // namespace cf
