// Tests of resample_mask_slices (mask_phantom_score.cpp): a mask built here, each slice marked with
// its own index, resampled to thicker and thinner slices.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "colonflat/core/error.h"
#include "colonflat/phantom/mask_phantom.h"

namespace cf {
namespace {

// A 3 x 2 x `nz` mask at 0.8 x 0.8 x `dz` mm whose every voxel of slice k holds k (so a resampled
// slice names the slice it came from), with a non-trivial origin and a flipped direction.
MaskImage::Pointer indexed_slices(std::size_t nz, double dz) {
  auto m = MaskImage::New();
  MaskImage::SizeType size = {{3, 2, nz}};
  m->SetRegions(size);
  m->SetSpacing(MaskImage::SpacingType(std::array<double, 3>{0.8, 0.8, dz}.data()));
  MaskImage::PointType origin;
  origin[0] = 12.5, origin[1] = -40.0, origin[2] = 100.25;
  m->SetOrigin(origin);
  MaskImage::DirectionType dir;
  dir.SetIdentity();
  dir(0, 0) = -1, dir(1, 1) = -1;
  m->SetDirection(dir);
  m->Allocate();
  for (std::size_t k = 0; k < nz; ++k)
    for (std::size_t j = 0; j < 2; ++j)
      for (std::size_t i = 0; i < 3; ++i) m->SetPixel({{long(i), long(j), long(k)}}, static_cast<unsigned char>(k));
  return m;
}

// 1 mm slices to 1.25 mm: floor(10 * 1 / 1.25) + 1 = 9 slices spanning the same 10 mm, slice k the
// source slice nearest to k * 1.25 mm (rounded half away from zero), in-plane size, spacing, origin
// and direction unchanged.
TEST(MaskResampleSlices, ThickerSlicesTakeTheNearestSourceSlice) {
  const MaskImage::Pointer in = indexed_slices(11, 1.0);
  const MaskImage::Pointer out = resample_mask_slices(in.GetPointer(), 1.25);
  const auto size = out->GetLargestPossibleRegion().GetSize();
  ASSERT_EQ(size[2], 9u);
  EXPECT_EQ(size[0], 3u);
  EXPECT_EQ(size[1], 2u);
  EXPECT_DOUBLE_EQ(out->GetSpacing()[2], 1.25);
  EXPECT_DOUBLE_EQ(out->GetSpacing()[0], 0.8);
  EXPECT_EQ(out->GetOrigin(), in->GetOrigin());
  EXPECT_EQ(out->GetDirection(), in->GetDirection());
  for (long k = 0; k < 9; ++k) {
    const long expected = std::lround(double(k) * 1.25);
    EXPECT_EQ(out->GetPixel({{2, 1, k}}), expected) << "slice " << k;
    // The slice's centre lies within half a source slice of the source slice it copies.
    MaskImage::PointType p_out, p_in;
    out->TransformIndexToPhysicalPoint({{0, 0, k}}, p_out);
    in->TransformIndexToPhysicalPoint({{0, 0, expected}}, p_in);
    EXPECT_LE(std::abs(p_out[2] - p_in[2]), 0.5 + 1e-9);
  }
}

// Thinner slices (2.5 mm to 1 mm) repeat source slices and never read past the last one.
TEST(MaskResampleSlices, ThinnerSlicesRepeatSourceSlices) {
  const MaskImage::Pointer out = resample_mask_slices(indexed_slices(4, 2.5).GetPointer(), 1.0);
  const auto size = out->GetLargestPossibleRegion().GetSize();
  ASSERT_EQ(size[2], 8u);  // floor(3 * 2.5 / 1) + 1
  for (long k = 0; k < 8; ++k) EXPECT_EQ(out->GetPixel({{0, 0, k}}), std::min(3L, std::lround(double(k) / 2.5)));
}

// A slice spacing that is not positive is refused as a usage error.
TEST(MaskResampleSlices, NonPositiveSpacingIsRefused) {
  const MaskImage::Pointer in = indexed_slices(3, 1.0);
  EXPECT_THROW(resample_mask_slices(in.GetPointer(), 0.0), UsageError);
  EXPECT_THROW(resample_mask_slices(in.GetPointer(), -1.0), UsageError);
  EXPECT_THROW(resample_mask_slices(in.GetPointer(), std::nan("")), UsageError);
}

}  // namespace
}  // namespace cf
