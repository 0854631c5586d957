// Scoring a segmentation against a painted case (Dice, colon fluid kept, volume outside the colon)
// block-majority downsampling of a mask and its resampling to another slice spacing.
#include <itkSignedMaurerDistanceMapImageFilter.h>

#include <algorithm>
#include <array>

#include "colonflat/core/error.h"
#include "colonflat/phantom/mask_phantom.h"

namespace cf {

MaskSegmentationScore score_segmentation(const MaskImage* seg, const Phantom& truth, double outside_mm) {
  const MaskImage* gt = truth.lumen.GetPointer();
  if (seg->GetLargestPossibleRegion().GetSize() != gt->GetLargestPossibleRegion().GetSize())
    throw PreconditionError("score_segmentation: the segmentation is not on the truth's grid");
  auto dm = itk::SignedMaurerDistanceMapImageFilter<MaskImage, itk::Image<float, 3>>::New();
  dm->SetInput(gt);
  dm->SetUseImageSpacing(true);
  dm->SetSquaredDistance(false);
  dm->SetInsideIsPositive(false);
  dm->Update();
  const float* dist = dm->GetOutput()->GetBufferPointer();
  const unsigned char *a = gt->GetBufferPointer(), *b = seg->GetBufferPointer(), *lab = truth.labels->GetBufferPointer();
  const std::size_t n = gt->GetLargestPossibleRegion().GetNumberOfPixels();
  std::size_t inter = 0, sa = 0, sb = 0, fluid = 0, fluid_kept = 0, outside = 0, bowel = 0, bladder = 0;
  for (std::size_t q = 0; q < n; ++q) {
    inter += a[q] && b[q];
    sa += a[q] != 0;
    sb += b[q] != 0;
    fluid += lab[q] == 2;
    fluid_kept += lab[q] == 2 && b[q];
    outside += b[q] && dist[q] > outside_mm;
    bowel += b[q] && (lab[q] == 3 || lab[q] == 4);
    bladder += b[q] && lab[q] == 5;
  }
  const auto sp = gt->GetSpacing();
  const double ml = sp[0] * sp[1] * sp[2] / 1000.0;
  MaskSegmentationScore s;
  s.dice = sa + sb ? 2.0 * double(inter) / double(sa + sb) : 1.0;
  s.fluid_kept = fluid ? double(fluid_kept) / double(fluid) : 1.0;
  s.fluid_ml = fluid * ml;
  s.outside_ml = outside * ml;
  s.small_bowel_ml = bowel * ml;
  s.bladder_ml = bladder * ml;
  return s;
}

std::vector<MaskBodyScore> score_fluid_bodies(const MaskImage* seg, const MaskPhantom& truth) {
  std::vector<std::array<double, 5>> acc(truth.bodies.size() + 1, {0, 0, 0, 0, 0});
  const unsigned char* m = seg->GetBufferPointer();
  const auto n = seg->GetLargestPossibleRegion().GetSize();
  if (truth.fluid_id.size() != n[0] * n[1] * n[2]) throw PreconditionError("score_fluid_bodies: the segmentation is not on the truth's grid");
  for (std::size_t q = 0; q < truth.fluid_id.size(); ++q)
    if (truth.fluid_id[q]) {
      auto& a = acc[truth.fluid_id[q]];
      a[0] += 1, a[1] += m[q] != 0, a[2] += double(q % n[0]), a[3] += double(q / n[0] % n[1]), a[4] += double(q / n[0] / n[1]);
    }
  const auto sp = seg->GetSpacing();
  std::vector<MaskBodyScore> out;
  for (std::size_t b = 1; b < acc.size(); ++b) {
    MaskBodyScore s;
    s.body = b;
    s.ml = acc[b][0] * sp[0] * sp[1] * sp[2] / 1000;
    s.kept = acc[b][1] / std::max(1.0, acc[b][0]);
    itk::ContinuousIndex<double, 3> c;
    for (int d = 0; d < 3; ++d) c[d] = acc[b][2 + d] / std::max(1.0, acc[b][0]);
    MaskImage::PointType pt;
    seg->TransformContinuousIndexToPhysicalPoint(c, pt);
    s.centroid_lps = {pt[0], pt[1], pt[2]};
    out.push_back(s);
  }
  return out;
}

MaskImage::Pointer resample_mask_slices(const MaskImage* m, double slice_mm) {
  if (!(slice_mm > 0)) throw UsageError("resample_mask_slices: the slice spacing must be > 0");
  const auto in = m->GetLargestPossibleRegion().GetSize();
  const double sz_in = m->GetSpacing()[2];
  const auto nz = std::size_t(std::max(1.0, std::floor((double(in[2]) - 1) * sz_in / slice_mm) + 1));
  MaskImage::SizeType sz = in;
  sz[2] = nz;
  MaskImage::SpacingType sp = m->GetSpacing();
  sp[2] = slice_mm;
  auto out = MaskImage::New();
  out->SetRegions(sz);
  out->SetSpacing(sp);
  out->SetOrigin(m->GetOrigin());
  out->SetDirection(m->GetDirection());
  out->Allocate();
  const std::size_t plane = in[0] * in[1];
  for (std::size_t k = 0; k < nz; ++k) {
    const auto src = std::min(in[2] - 1, std::size_t(std::lround(double(k) * slice_mm / sz_in)));
    std::copy_n(m->GetBufferPointer() + src * plane, plane, out->GetBufferPointer() + k * plane);
  }
  return out;
}

MaskImage::Pointer downsample_mask(const MaskImage* m, const std::array<int, 3>& f) {
  const auto in = m->GetLargestPossibleRegion().GetSize();
  MaskImage::SizeType sz;
  MaskImage::SpacingType sp;
  for (int d = 0; d < 3; ++d) {
    if (f[d] < 1) throw UsageError("downsample_mask: factors must be >= 1");
    sz[d] = in[d] / std::size_t(f[d]);
    sp[d] = m->GetSpacing()[d] * f[d];
  }
  MaskImage::PointType org;
  itk::ContinuousIndex<double, 3> c;
  for (int d = 0; d < 3; ++d) c[d] = 0.5 * (f[d] - 1);
  m->TransformContinuousIndexToPhysicalPoint(c, org);
  auto out = MaskImage::New();
  out->SetRegions(sz);
  out->SetSpacing(sp);
  out->SetOrigin(org);
  out->SetDirection(m->GetDirection());
  out->Allocate();
  const unsigned char* a = m->GetBufferPointer();
  unsigned char* b = out->GetBufferPointer();
  const int need = (f[0] * f[1] * f[2]) / 2 + 1;
  for (std::size_t k = 0; k < sz[2]; ++k)
    for (std::size_t j = 0; j < sz[1]; ++j)
      for (std::size_t i = 0; i < sz[0]; ++i) {
        int on = 0;
        for (int dk = 0; dk < f[2]; ++dk)
          for (int dj = 0; dj < f[1]; ++dj)
            for (int di = 0; di < f[0]; ++di)
              on += a[(i * f[0] + di) + in[0] * ((j * f[1] + dj) + in[1] * (k * f[2] + dk))] != 0;
        b[i + sz[0] * (j + sz[1] * k)] = on >= need ? 1 : 0;
      }
  return out;
}

}  // namespace cf
