// The benches' varied real anatomy (mask_variants.h): a mask grown, shrunk and padded with empty slices.
#include <gtest/gtest.h>

#include "mask_variants.h"

namespace {

using cf::MaskImage;

// A 12 x 12 x 12 mask with spacing 0.8 x 0.8 x 1.25 mm and origin (-10, 20, 30), empty.
MaskImage::Pointer empty_mask() {
  auto m = MaskImage::New();
  MaskImage::RegionType region;
  region.SetSize({12, 12, 12});
  m->SetRegions(region);
  m->SetSpacing(itk::Vector<double, 3>(std::array<double, 3>{0.8, 0.8, 1.25}.data()));
  const double origin[3] = {-10, 20, 30};
  m->SetOrigin(origin);
  m->Allocate(true);
  return m;
}

std::size_t lumen_voxels(const MaskImage* m) {
  std::size_t n = 0;
  const unsigned char* p = m->GetBufferPointer();
  for (std::size_t i = 0; i < m->GetLargestPossibleRegion().GetNumberOfPixels(); ++i) n += p[i] != 0;
  return n;
}

}  // namespace

// One lumen voxel grown by one voxel reaches its 6 face neighbours and no voxel two steps away;
// shrunk again it is the one voxel (a closing of a point); the geometry is kept.
TEST(BenchMasks, PointGrownReachesItsNeighboursAndShrinksBack) {
  MaskImage::Pointer m = empty_mask();
  m->SetPixel({6, 6, 6}, 1);
  const MaskImage::Pointer grown = cf::bench::grown_mask(m.GetPointer(), 1);
  for (const auto& idx : {MaskImage::IndexType{5, 6, 6}, {7, 6, 6}, {6, 5, 6}, {6, 7, 6}, {6, 6, 5}, {6, 6, 7}})
    EXPECT_EQ(grown->GetPixel(idx), 1) << idx;
  EXPECT_EQ(grown->GetPixel({8, 6, 6}), 0);
  EXPECT_EQ(grown->GetPixel({7, 7, 7}), 0);  // a corner: sqrt(3) voxels away
  EXPECT_GE(lumen_voxels(grown.GetPointer()), 7u);
  EXPECT_EQ(grown->GetSpacing(), m->GetSpacing());
  EXPECT_EQ(grown->GetOrigin(), m->GetOrigin());
  const MaskImage::Pointer back = cf::bench::grown_mask(grown.GetPointer(), -1);
  EXPECT_EQ(lumen_voxels(back.GetPointer()), 1u);
  EXPECT_EQ(back->GetPixel({6, 6, 6}), 1);
}

// Two lumen slabs 2 voxels apart (a thin wall between touching loops) are joined by growing one
// voxel and not by 0; a 1-voxel-thick strand vanishes when shrunk.
TEST(BenchMasks, ThinWallFusesWhenGrownAndThinStrandOpensWhenShrunk) {
  MaskImage::Pointer m = empty_mask();
  for (int y = 1; y < 11; ++y)
    for (int z = 1; z < 11; ++z)
      for (int x : {2, 3, 4, 7, 8, 9}) m->SetPixel({x, y, z}, 1);  // the wall: x = 5, 6
  EXPECT_EQ(cf::bench::grown_mask(m.GetPointer(), 0)->GetPixel({5, 5, 5}), 0);
  const MaskImage::Pointer grown = cf::bench::grown_mask(m.GetPointer(), 1);
  EXPECT_EQ(grown->GetPixel({5, 5, 5}), 1);
  EXPECT_EQ(grown->GetPixel({6, 5, 5}), 1);
  MaskImage::Pointer strand = empty_mask();
  for (int x = 1; x < 11; ++x) strand->SetPixel({x, 6, 6}, 1);
  EXPECT_EQ(lumen_voxels(cf::bench::grown_mask(strand.GetPointer(), -1).GetPointer()), 0u);
}

// Padding adds empty slices after the last one and moves nothing: the same origin, spacing and
// direction, every original voxel in place, the new slices 0, the lumen count unchanged.
TEST(BenchMasks, PaddedSlicesAreEmptyAndTheGeometryIsKept) {
  MaskImage::Pointer m = empty_mask();
  m->SetPixel({6, 6, 11}, 1);
  m->SetPixel({2, 3, 0}, 1);
  const MaskImage::Pointer p = cf::bench::padded_mask(m.GetPointer(), 5);
  const auto size = p->GetLargestPossibleRegion().GetSize();
  EXPECT_EQ(size[0], 12u);
  EXPECT_EQ(size[1], 12u);
  EXPECT_EQ(size[2], 17u);
  EXPECT_EQ(p->GetLargestPossibleRegion().GetIndex(), m->GetLargestPossibleRegion().GetIndex());
  EXPECT_EQ(p->GetOrigin(), m->GetOrigin());
  EXPECT_EQ(p->GetSpacing(), m->GetSpacing());
  EXPECT_EQ(p->GetDirection(), m->GetDirection());
  EXPECT_EQ(p->GetPixel({6, 6, 11}), 1);
  EXPECT_EQ(p->GetPixel({2, 3, 0}), 1);
  EXPECT_EQ(lumen_voxels(p.GetPointer()), 2u);
  for (int k = 12; k < 17; ++k) EXPECT_EQ(p->GetPixel({6, 6, k}), 0) << k;
  EXPECT_EQ(lumen_voxels(cf::bench::padded_mask(m.GetPointer(), 0).GetPointer()), 2u);
}
