#pragma once
// Synthetic CT volumes for the segmentation tests: a box of soft tissue (40 HU) in outside air,
// 1 mm voxels, painted by a function, blurred and with noise; mask comparisons.
#include <itkConnectedComponentImageFilter.h>
#include <itkSmoothingRecursiveGaussianImageFilter.h>

#include <cmath>
#include <functional>
#include <string>

#include "colonflat/segment/segment.h"

namespace cf {

inline const double kKeep = std::nan("");  // keep the tissue value

// A synthetic "abdomen": a box of soft tissue (40 HU) inside air that touches the volume border,
// voxel size 1 mm; `paint(x, y, z)` may return another HU value (or kKeep to keep tissue).
inline CtImage::Pointer make_volume(int n, const std::function<double(double, double, double)>& paint, double blur = 0.6,
                             double noise = 0) {
  auto im = CtImage::New();
  CtImage::SizeType sz{{std::size_t(n), std::size_t(n), std::size_t(n)}};
  im->SetRegions(sz);
  const double sp[3] = {1, 1, 1};
  im->SetSpacing(sp);
  im->Allocate();
  std::uint64_t state = 12345;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const bool body = i >= 4 && j >= 4 && i < n - 4 && j < n - 4;
        double v = body ? 40 : -1000;
        if (body) {
          const double p = paint(i, j, k);
          if (!std::isnan(p)) v = p;  // kKeep: tissue
        }
        im->SetPixel({{std::size_t(i), std::size_t(j), std::size_t(k)}}, float(v));
      }
  CtImage::Pointer out = im;
  if (blur > 0) {
    auto sm = itk::SmoothingRecursiveGaussianImageFilter<CtImage, CtImage>::New();
    sm->SetInput(im);
    sm->SetSigma(blur);
    sm->Update();
    out = sm->GetOutput();
    out->DisconnectPipeline();
  }
  if (noise > 0) {
    float* b = out->GetBufferPointer();
    for (std::size_t q = 0; q < out->GetLargestPossibleRegion().GetNumberOfPixels(); ++q) {
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      const double u = double(state >> 11) / 9007199254740992.0 - 0.5;
      b[q] += float(noise * 3.4 * u);
    }
  }
  return out;
}

inline std::size_t count(const MaskImage* m) {
  std::size_t c = 0;
  for (std::size_t q = 0; q < m->GetLargestPossibleRegion().GetNumberOfPixels(); ++q) c += m->GetBufferPointer()[q] != 0;
  return c;
}
inline bool at(const MaskImage* m, int i, int j, int k) { return m->GetPixel({{std::size_t(i), std::size_t(j), std::size_t(k)}}) != 0; }

inline double dice(const MaskImage* a, const MaskImage* b) {
  std::size_t inter = 0, sa = 0, sb = 0;
  for (std::size_t q = 0; q < a->GetLargestPossibleRegion().GetNumberOfPixels(); ++q) {
    inter += a->GetBufferPointer()[q] && b->GetBufferPointer()[q];
    sa += a->GetBufferPointer()[q] != 0;
    sb += b->GetBufferPointer()[q] != 0;
  }
  return 2.0 * double(inter) / double(sa + sb);
}

inline std::size_t components(const MaskImage* m) {
  auto cc = itk::ConnectedComponentImageFilter<MaskImage, itk::Image<std::uint32_t, 3>>::New();
  cc->SetInput(m);
  cc->Update();
  return cc->GetObjectCount();
}

// Whether the report holds a decision (`kept` / `rejected`) whose reason contains `part`.
inline bool has_reason(const SegmentStats& st, const std::string& decision, const std::string& part) {
  for (const auto& d : st.decisions)
    if (d["decision"] == decision && d["reason"].get<std::string>().find(part) != std::string::npos) return true;
  return false;
}

inline SegmentOptions small_volume_options() {
  SegmentOptions o;
  o.min_segment_volume = 1;  // mL: the test volumes are small
  o.min_colon_volume = 1;
  return o;
}

}  // namespace cf
