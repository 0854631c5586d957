// Variations of a real lumen mask (see mask_variants.h).
#include "mask_variants.h"

#include <itkBinaryBallStructuringElement.h>
#include <itkBinaryDilateImageFilter.h>
#include <itkBinaryErodeImageFilter.h>
#include <itkImageDuplicator.h>

#include <cstdlib>

namespace cf::bench {

namespace {

using Ball = itk::BinaryBallStructuringElement<unsigned char, 3>;

Ball ball(int radius) {
  Ball b;
  b.SetRadius(radius);
  b.CreateStructuringElement();
  return b;
}

// One morphology filter (BinaryDilateImageFilter or BinaryErodeImageFilter) of `mask` by `b`.
template <class Filter>
MaskImage::Pointer apply(const MaskImage* mask, const Ball& b) {
  auto f = Filter::New();
  f->SetInput(mask);
  f->SetKernel(b);
  f->SetForegroundValue(1);
  f->SetBackgroundValue(0);
  f->Update();
  MaskImage::Pointer out = f->GetOutput();
  out->DisconnectPipeline();
  return out;
}

}  // namespace

MaskImage::Pointer grown_mask(const MaskImage* mask, int voxels) {
  if (voxels > 0) return apply<itk::BinaryDilateImageFilter<MaskImage, MaskImage, Ball>>(mask, ball(voxels));
  if (voxels < 0) return apply<itk::BinaryErodeImageFilter<MaskImage, MaskImage, Ball>>(mask, ball(std::abs(voxels)));
  auto copy = itk::ImageDuplicator<MaskImage>::New();
  copy->SetInputImage(mask);
  copy->Update();
  return copy->GetOutput();
}

}  // namespace cf::bench
