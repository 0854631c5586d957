// smooth_large_scale: the coarse-grid Gaussian against VTK's direct Gaussian on the fine grid.
#include <gtest/gtest.h>

#include <vtkImageData.h>
#include <vtkImageGaussianSmooth.h>
#include <vtkNew.h>

#include <algorithm>
#include <cmath>

#include "colonflat/core/error.h"
#include "colonflat/core/threads.h"
#include "colonflat/render/image_smooth.h"

namespace cf {
namespace {

// A w x h field of unit normals of a wavy wall (waves 40 and 23 px long), zero in a 30 px wide
// column of "no wall" and in a 12 px hole, like the view normals of a band with missing wall.
ImagePtr wavy_normals(int w, int h) {
  ImagePtr img = ImagePtr::New();
  img->SetDimensions(w, h, 1);
  img->AllocateScalars(VTK_DOUBLE, 3);
  auto* p = static_cast<double*>(img->GetScalarPointer());
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      const double gx = 0.6 * std::sin(2 * M_PI * i / 40.0), gy = 0.4 * std::cos(2 * M_PI * j / 23.0);
      const double n = std::sqrt(1 + gx * gx + gy * gy);
      const bool none = (i >= 150 && i < 180) || std::hypot(i - 60, j - 50) < 12;
      double* q = p + 3 * (std::size_t(j) * w + i);
      q[0] = none ? 0 : -gx / n, q[1] = none ? 0 : -gy / n, q[2] = none ? 0 : 1 / n;
    }
  return img;
}

ImagePtr vtk_gaussian(vtkImageData* img, double sigma) {
  vtkNew<vtkImageGaussianSmooth> s;
  s->SetInputData(img);
  s->SetDimensionality(2);
  s->SetStandardDeviations(sigma, sigma, 0);
  s->SetRadiusFactors(2.5, 2.5, 0);
  s->Update();
  ImagePtr out = s->GetOutput();
  return out;
}

double angle_deg(const double* a, const double* b) {
  const double d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const double na = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]), nb = std::sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
  return std::acos(std::clamp(d / (na * nb), -1.0, 1.0)) * 180 / M_PI;
}

// Below two coarse sigmas the image itself is smoothed: the output is VTK's Gaussian, bit for bit.
TEST(ImageSmooth, SmallSigmaIsVtksGaussianExactly) {
  ImagePtr img = wavy_normals(97, 61);
  ImagePtr a = smooth_large_scale(img, 5.0), b = vtk_gaussian(img, 5.0);
  const auto *pa = static_cast<const double*>(a->GetScalarPointer()), *pb = static_cast<const double*>(b->GetScalarPointer());
  for (int k = 0; k < 97 * 61 * 3; ++k) ASSERT_EQ(pa[k], pb[k]) << k;
}

// At the colon image's scale (sigma 16 px: 8 mm at 0.5 mm pixels) the coarse-grid result points
// within 1 degree of VTK's direct Gaussian wherever the smoothed wall normal is not near zero and
// the pixel is at least sigma from the image border (holes included), within 2 degrees at the border.
TEST(ImageSmooth, LargeSigmaMatchesDirectGaussianDirection) {
  const int w = 331, h = 203;  // not multiples of the block size: cut blocks at two borders
  const double sigma = 16;
  ImagePtr img = wavy_normals(w, h);
  ImagePtr a = smooth_large_scale(img, sigma), b = vtk_gaussian(img, sigma);
  const auto *pa = static_cast<const double*>(a->GetScalarPointer()), *pb = static_cast<const double*>(b->GetScalarPointer());
  double inner = 0, border = 0;
  int compared = 0;
  for (int k = 0; k < w * h; ++k) {
    const double* q = pb + 3 * k;
    if (std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]) < 0.2) continue;
    const int i = k % w, j = k / w;
    const bool at_border = std::min({i, j, w - 1 - i, h - 1 - j}) < sigma;
    double& worst = at_border ? border : inner;
    worst = std::max(worst, angle_deg(pa + 3 * k, q));
    ++compared;
  }
  EXPECT_GT(compared, w * h * 8 / 10);
  EXPECT_LT(inner, 1.0);
  EXPECT_LT(border, 2.0);
}

// The coarse path gives the same bits for any thread count.
TEST(ImageSmooth, SameResultForAnyThreadCount) {
  ImagePtr img = wavy_normals(211, 157);
  set_thread_count(1);
  ImagePtr one = smooth_large_scale(img, 12.0);
  set_thread_count(3);
  ImagePtr three = smooth_large_scale(img, 12.0);
  set_thread_count(0);
  const auto *p1 = static_cast<const double*>(one->GetScalarPointer()), *p3 = static_cast<const double*>(three->GetScalarPointer());
  for (int k = 0; k < 211 * 157 * 3; ++k) ASSERT_EQ(p1[k], p3[k]) << k;
}

// A float image or a non-positive sigma is refused with an error, not smoothed.
TEST(ImageSmooth, InvalidInputIsRejected) {
  ImagePtr f = ImagePtr::New();
  f->SetDimensions(8, 8, 1);
  f->AllocateScalars(VTK_FLOAT, 3);
  EXPECT_THROW(smooth_large_scale(f, 16.0), Error);
  EXPECT_THROW(smooth_large_scale(wavy_normals(8, 8), 0.0), Error);
}

}  // namespace
}  // namespace cf
