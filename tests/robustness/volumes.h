#pragma once
// Tiny volumes for the robustness suite, written through ITK (the formats' own writers).
#include <itkImageFileWriter.h>
#include <itkMetaImageIO.h>
#include <itkNiftiImageIO.h>
#include <itkNrrdImageIO.h>

#include "colonflat/volume/volume_io.h"
#include "support.h"

namespace cf::robust {

// A 24 x 20 x 16 CT-like float volume: air box inside soft tissue, values in HU.
inline CtImage::Pointer small_ct() {
  auto img = CtImage::New();
  CtImage::SizeType size{{24, 20, 16}};
  img->SetRegions(CtImage::RegionType(size));
  CtImage::SpacingType sp;
  sp[0] = sp[1] = 1.0;
  sp[2] = 1.5;
  img->SetSpacing(sp);
  img->Allocate();
  float* v = img->GetBufferPointer();
  for (unsigned k = 0; k < 16; ++k)
    for (unsigned j = 0; j < 20; ++j)
      for (unsigned i = 0; i < 24; ++i)
        v[(k * 20 + j) * 24 + i] = (i > 5 && i < 18 && j > 5 && j < 14 && k > 3 && k < 12) ? -1000.f : 40.f;
  return img;
}

// Writes `img` with ITK to `path` (format by extension), compressed or raw.
template <class TImage>
void write_itk(const TImage* img, const fs::path& path, bool compress) {
  auto w = itk::ImageFileWriter<TImage>::New();
  const std::string ext = full_extension(path);  // IO chosen here: the build registers no factories
  if (ext == ".nrrd") w->SetImageIO(itk::NrrdImageIO::New());
  else if (ext == ".mha") w->SetImageIO(itk::MetaImageIO::New());
  else w->SetImageIO(itk::NiftiImageIO::New());
  w->SetInput(img);
  w->SetFileName(path.string());
  w->SetUseCompression(compress);
  w->Update();
}

}  // namespace cf::robust
