// Variations of a real lumen mask (see mask_variants.h).
#include "mask_variants.h"

#include <itkBinaryBallStructuringElement.h>
#include <itkBinaryDilateImageFilter.h>
#include <itkBinaryErodeImageFilter.h>
#include <itkConstantPadImageFilter.h>
#include <itkImageDuplicator.h>

#include <algorithm>
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

MaskImage::Pointer padded_mask(const MaskImage* mask, int slices) {
  auto pad = itk::ConstantPadImageFilter<MaskImage, MaskImage>::New();
  pad->SetInput(mask);
  MaskImage::SizeType after{{0, 0, static_cast<MaskImage::SizeValueType>(std::max(slices, 0))}};
  pad->SetPadUpperBound(after);
  pad->SetConstant(0);
  pad->Update();
  MaskImage::Pointer out = pad->GetOutput();
  out->DisconnectPipeline();
  return out;
}

}  // namespace cf::bench
