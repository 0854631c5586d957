#include "colonflat/render/image_smooth.h"

#include <vtkImageData.h>
#include <vtkImageGaussianSmooth.h>
#include <vtkNew.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "colonflat/core/error.h"
#include "colonflat/core/threads.h"

namespace cf {
namespace {

ImagePtr gaussian(vtkImageData* image, double sigma_px) {
  vtkNew<vtkImageGaussianSmooth> smooth;
  smooth->SetInputData(image);
  smooth->SetDimensionality(2);
  smooth->SetStandardDeviations(sigma_px, sigma_px, 0);
  smooth->SetRadiusFactors(2.5, 2.5, 0);
  smooth->Update();
  ImagePtr out = smooth->GetOutput();
  return out;
}

ImagePtr new_image(int w, int h, int comps) {
  ImagePtr img = ImagePtr::New();
  img->SetDimensions(w, h, 1);
  img->AllocateScalars(VTK_DOUBLE, comps);
  return img;
}

// The mean of every f x f block (the last row and column of blocks may be cut by the border).
ImagePtr block_means(vtkImageData* image, int f) {
  const int* d = image->GetDimensions();
  const int w = d[0], h = d[1], nc = image->GetNumberOfScalarComponents();
  const int cw = (w + f - 1) / f, ch = (h + f - 1) / f;
  ImagePtr out = new_image(cw, ch, nc);
  const auto* in = static_cast<const double*>(image->GetScalarPointer());
  auto* o = static_cast<double*>(out->GetScalarPointer());
  parallel_for(std::size_t(ch), [&](std::size_t r0, std::size_t r1) {
    for (int r = int(r0); r < int(r1); ++r)
      for (int c = 0; c < cw; ++c) {
        const int j1 = std::min(h, (r + 1) * f), i1 = std::min(w, (c + 1) * f);
        double* dst = o + (std::size_t(r) * cw + c) * nc;
        std::fill(dst, dst + nc, 0.0);
        for (int j = r * f; j < j1; ++j)
          for (int i = c * f; i < i1; ++i)
            for (int k = 0; k < nc; ++k) dst[k] += in[(std::size_t(j) * w + i) * nc + k];
        const double n = double((j1 - r * f) * (i1 - c * f));
        for (int k = 0; k < nc; ++k) dst[k] /= n;
      }
  });
  return out;
}

// Where fine pixel `fine` (of `fine_n`) falls between the centres of the f-pixel blocks: lo, hi and
// the weight t of hi. A block's centre is the mean of its pixels' (the last block may be cut short);
// beyond the outermost centres the nearest one holds (t = 0 or 1).
struct CoarseAxis {
  int lo = 0, hi = 0;
  double t = 0;
  CoarseAxis(int fine, int f, int fine_n, int coarse_n) {
    auto centre = [&](int c) { return 0.5 * (c * f + std::min(fine_n, (c + 1) * f) - 1); };
    lo = std::clamp(int(std::floor((fine - 0.5 * (f - 1)) / f)), 0, coarse_n - 1);
    hi = std::min(lo + 1, coarse_n - 1);
    if (hi > lo) t = std::clamp((fine - centre(lo)) / (centre(hi) - centre(lo)), 0.0, 1.0);
  }
};

ImagePtr upsample(vtkImageData* coarse, int f, int w, int h) {
  const int* d = coarse->GetDimensions();
  const int cw = d[0], ch = d[1], nc = coarse->GetNumberOfScalarComponents();
  ImagePtr out = new_image(w, h, nc);
  const auto* c = static_cast<const double*>(coarse->GetScalarPointer());
  auto* o = static_cast<double*>(out->GetScalarPointer());
  std::vector<CoarseAxis> columns;  // the same for every row
  columns.reserve(std::size_t(w));
  for (int i = 0; i < w; ++i) columns.emplace_back(i, f, w, cw);
  parallel_for(std::size_t(h), [&](std::size_t j0, std::size_t j1) {
    for (int j = int(j0); j < int(j1); ++j) {
      const CoarseAxis y(j, f, h, ch);
      for (int i = 0; i < w; ++i) {
        const CoarseAxis& x = columns[std::size_t(i)];
        for (int k = 0; k < nc; ++k) {
          auto at = [&](int r, int q) { return c[(std::size_t(r) * cw + q) * nc + k]; };
          const double lo = (1 - x.t) * at(y.lo, x.lo) + x.t * at(y.lo, x.hi);
          const double hi = (1 - x.t) * at(y.hi, x.lo) + x.t * at(y.hi, x.hi);
          o[(std::size_t(j) * w + i) * nc + k] = (1 - y.t) * lo + y.t * hi;
        }
      }
    }
  });
  return out;
}

}  // namespace

ImagePtr smooth_large_scale(vtkImageData* image, double sigma_px) {
  if (!image || image->GetScalarType() != VTK_DOUBLE || image->GetDimensions()[2] != 1 || !(sigma_px > 0))
    throw Error("smooth_large_scale: needs a 2D double image and sigma > 0");
  const int f = int(std::floor(sigma_px / kCoarseSigmaPx));
  if (f < 2) return gaussian(image, sigma_px);
  const int* d = image->GetDimensions();
  ImagePtr smoothed = gaussian(block_means(image, f), sigma_px / f);
  ImagePtr out = upsample(smoothed, f, d[0], d[1]);
  out->SetOrigin(image->GetOrigin());
  out->SetSpacing(image->GetSpacing());
  return out;
}

}  // namespace cf
