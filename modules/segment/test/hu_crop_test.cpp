// The segmenter's CT crop (hu_crop.h): 16 bits exactly when the CT holds integers, the same values
// read either way, and the same box means and segmentation as the float path.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "../src/segment_internal.h"
#include "segment_dims.h"
#include "segment_volumes.h"

namespace cf::segment_detail {
namespace {

// A crop of rows 2 .. 5 (x from 1, 6 voxels) of every slice of an 8 x 8 x 3 volume, and its values
// read back against the volume's.
HuCrop crop_of(const std::vector<float>& v) {
  HuCrop c;
  c.copy(v.data(), 4 * 3, 6, [](std::size_t r) { return (r / 4) * 64 + (2 + r % 4) * 8 + 1; });
  for (std::size_t r = 0; r < 12; ++r)
    for (std::size_t i = 0; i < 6; ++i) {
      const float want = v[(r / 4) * 64 + (2 + r % 4) * 8 + 1 + i];
      if (std::isnan(want)) EXPECT_TRUE(std::isnan(c[r * 6 + i]));
      else EXPECT_EQ(c[r * 6 + i], want) << r << " " << i;
    }
  EXPECT_EQ(c.size(), 72u);
  return c;
}

// Integer HU in [-32768, 32767] are held in 16 bits; one crop voxel with a fraction, out of range or
// NaN keeps the crop in float; a fraction outside the crop does not. Every value reads back exactly.
TEST(HuCrop, SixteenBitsExactlyWhenTheCropHoldsIntegers) {
  std::vector<float> v(8 * 8 * 3);
  for (std::size_t q = 0; q < v.size(); ++q) v[q] = float(int(q * 37 % 2000) - 1024);
  v[5] = -32768, v[6] = 32767;
  EXPECT_TRUE(crop_of(v).narrow());
  v[0] = 0.5f;  // outside the crop (row 0)
  EXPECT_TRUE(crop_of(v).narrow());
  for (float odd : {40.5f, 32768.0f, -32769.0f, std::nanf("")}) {
    std::vector<float> w = v;
    w[64 + 3 * 8 + 4] = odd;  // slice 1, row 3, x 4: inside
    EXPECT_FALSE(crop_of(w).narrow()) << odd;
  }
}

// The 3 x 3 x 3 box means of 16-bit HU equal, bit for bit, those of the same values as floats.
TEST(HuCrop, BoxMeansOfSixteenBitsEqualTheFloatMeans) {
  const Dims d = unit_dims(37, 23, 11);
  std::mt19937 rng(3);
  std::vector<float> f(d.total);
  std::vector<std::int16_t> s(d.total);
  for (std::size_t q = 0; q < d.total; ++q) s[q] = std::int16_t(int(rng() % 4000) - 1024), f[q] = s[q];
  std::vector<float> from_float(d.total), from_short(d.total);
  box_mean3_slices(f.data(), d, [&](std::size_t k, const float* m) { std::copy_n(m, 37 * 23, from_float.data() + k * 37 * 23); });
  box_mean3_slices(s.data(), d, [&](std::size_t k, const float* m) { std::copy_n(m, 37 * 23, from_short.data() + k * 37 * 23); });
  EXPECT_EQ(std::memcmp(from_float.data(), from_short.data(), d.total * sizeof(float)), 0);
}

// A CT rounded to whole HU is segmented in 16 bits; the same CT with a quarter HU added to one air
// voxel inside the lumen (so inside the crop) goes the float path: the same lumen, voxel for voxel,
// and volume.
TEST(HuCrop, SegmentationIsTheSameOnBothPaths) {
  auto ct = make_volume(64, [&](double x, double y, double z) {
    const double d = std::sqrt((x - 32) * (x - 32) + (y - 32) * (y - 32));
    if (d >= 14 || z < 8 || z > 56) return kKeep;
    return y > 36 ? 450.0 : -1000.0;
  }, 1.0, 10);
  float* b = ct->GetBufferPointer();
  const std::size_t n = ct->GetLargestPossibleRegion().GetNumberOfPixels();
  for (std::size_t q = 0; q < n; ++q) b[q] = std::nearbyint(b[q]);
  SegmentStats narrow, wide;
  auto a = segment_colon(ct, small_volume_options(), &narrow);
  b[32 + 64 * (28 + 64 * 32)] += 0.25f;  // (32, 28, 32): gas, 4 mm from the tube's axis
  auto c = segment_colon(ct, small_volume_options(), &wide);
  EXPECT_EQ(count(a), count(c));
  EXPECT_EQ(dice(a, c), 1.0);
  EXPECT_EQ(narrow.lumen_volume_ml, wide.lumen_volume_ml);
  EXPECT_EQ(narrow.segments, 1);
}

}  // namespace
}  // namespace cf::segment_detail
