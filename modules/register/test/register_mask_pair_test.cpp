// The real-mask test pairs of register_bench --real-mask (testdata mask_pair.h) on a tiny straight
// tube mask built here: path distance along the lumen, polyps on the wall, cuts and table moves.
#include <gtest/gtest.h>

#include <cmath>

#include "colonflat/testdata/mask_pair.h"

namespace cf {
namespace {

// A tube of radius 6 mm along the superior axis, z = 2..77 mm, 1 mm voxels.
MaskImage::Pointer tube() {
  auto m = MaskImage::New();
  MaskImage::SizeType size = {{24, 24, 80}};
  m->SetRegions(MaskImage::RegionType({{0, 0, 0}}, size));
  m->Allocate(true);
  for (long z = 2; z < 78; ++z)
    for (long y = 0; y < 24; ++y)
      for (long x = 0; x < 24; ++x)
        if ((x - 12) * (x - 12) + (y - 12) * (y - 12) <= 36) m->SetPixel({{x, y, z}}, 1);
  return m;
}

long lumen_in_slice(const MaskImage* m, long z) {
  long n = 0;
  for (long y = 0; y < 24; ++y)
    for (long x = 0; x < 24; ++x) n += m->GetPixel({{x, y, z}});
  return n;
}

// Path distance runs from the most inferior voxel along the tube: 75 mm long (plus at most the
// diagonal to the rim), 38 mm at z = 40 on the axis.
TEST(RegisterMaskPair, PathDistanceFollowsTheLumen) {
  MaskCourse c(tube());
  EXPECT_GE(c.length_mm(), 75.0);
  EXPECT_LE(c.length_mm(), 84.0);
  EXPECT_NEAR(c.path_at({12, 12, 40}), 38.0, 6.5);
  EXPECT_TRUE(std::isnan(c.path_at({12, 12, 200})));  // farther than 15 mm from the lumen
}

// Polyps sit on the wall (5-7 mm from the axis), 6, 7, 8 mm wide, in order along the course, and
// remove lumen (soft tissue bulging into it).
TEST(RegisterMaskPair, PolypsAreOnTheWallInOrder) {
  MaskCourse c(tube());
  long before = 0;
  for (long z = 0; z < 80; ++z) before += lumen_in_slice(c.mask(), z);
  const auto polyps = c.place_polyps(3, 1);
  ASSERT_EQ(polyps.size(), 3u);
  long after = 0;
  for (long z = 0; z < 80; ++z) after += lumen_in_slice(c.mask(), z);
  EXPECT_LT(after, before - 50);
  for (size_t k = 0; k < 3; ++k) {
    const double r = std::hypot(polyps[k].lps.x() - 12, polyps[k].lps.y() - 12);
    EXPECT_GE(r, 4.5) << k;
    EXPECT_LE(r, 6.5) << k;
    EXPECT_DOUBLE_EQ(polyps[k].diameter_mm, 6.0 + double(k));
    if (k > 0) EXPECT_GT(polyps[k].path_mm, polyps[k - 1].path_mm + 20);
  }
}

// A cut removes exactly the lumen of its path range; the move shifts the origin (table) and turns
// the direction, and moved() maps the unmoved point to where the moved image has it.
TEST(RegisterMaskPair, CutAndMove) {
  MaskCourse c(tube());
  const MaskImage::Pointer m = c.cut_and_move({{30, 45}}, {5, -3, 20}, 10);
  EXPECT_EQ(lumen_in_slice(m, 40), 0);
  EXPECT_EQ(lumen_in_slice(m, 60), lumen_in_slice(c.mask(), 60));
  EXPECT_GT(lumen_in_slice(m, 20), 0);
  MaskImage::PointType p;
  m->TransformIndexToPhysicalPoint({{12, 12, 60}}, p);
  const Eigen::Vector3d expected = MaskCourse::moved({12, 12, 60}, c.centroid(), {5, -3, 20}, 10);
  EXPECT_NEAR((Eigen::Vector3d(p[0], p[1], p[2]) - expected).norm(), 0.0, 1e-9);
}

}  // namespace
}  // namespace cf
