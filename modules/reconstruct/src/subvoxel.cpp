// The sub-voxel field the surface is extracted from (docs/reconstruct.md, "Sub-voxel surface").
// Every variant ends with the same constraint: the field is > 0.5 exactly at lumen voxels, so the
// isosurface keeps the binary mask's triangles and each vertex stays on its lattice edge, strictly
// between the centres of the lumen voxel and the background voxel it separates (< 1/2 voxel from
// the raw staircase surface).
#include <itkAntiAliasBinaryImageFilter.h>
#include <itkImage.h>
#include <vtkNew.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>
#include <vector>

#include "colonflat/core/box_dilation.h"
#include "colonflat/core/error.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/core/threads.h"
#include "reconstruct_internal.h"

namespace cf::reconstruct_detail {
namespace {

using FloatImage = itk::Image<float, 3>;

// Index-space dimensions of a VTK image as size_t.
std::array<std::size_t, 3> dims_of(vtkImageData* img) {
  int d[3];
  img->GetDimensions(d);
  return {std::size_t(d[0]), std::size_t(d[1]), std::size_t(d[2])};
}

// A float ITK image over the padded crop (physical spacing in mm so that filters work in mm),
// holding the binary values.
FloatImage::Pointer to_itk_float(vtkImageData* binary, const std::array<double, 3>& spacing) {
  const auto n = dims_of(binary);
  auto img = FloatImage::New();
  FloatImage::RegionType region;
  FloatImage::SpacingType sp;
  for (int a = 0; a < 3; ++a) {
    region.SetSize(a, n[a]);
    sp[a] = spacing[a];
  }
  img->SetRegions(region);
  img->SetSpacing(sp);
  img->Allocate();
  const auto* src = static_cast<const unsigned char*>(binary->GetScalarPointer());
  float* dst = img->GetBufferPointer();
  const std::size_t count = n[0] * n[1] * n[2];
  for (std::size_t i = 0; i < count; ++i) dst[i] = float(src[i]);
  return img;
}

// Whitaker's constrained curvature flow (ITK's anti-alias filter): the smoothest level set that
// keeps every voxel on its side. Writes a field in [0, 1]-ish units, > 0.5 inside (the sign is
// decided from the lumen voxels, whatever ITK's convention).
void antialias_field(const FloatImage::Pointer& binary, const ReconstructOptions& o, float* out) {
  using Filter = itk::AntiAliasBinaryImageFilter<FloatImage, FloatImage>;
  auto filter = Filter::New();
  filter->SetInput(binary);
  filter->SetMaximumRMSError(o.antialias_rms);
  filter->SetNumberOfIterations(unsigned(o.antialias_iterations));
  filter->SetNumberOfLayers(2);
  filter->Update();
  const FloatImage* level = filter->GetOutput();
  const float* phi = level->GetBufferPointer();
  const float* inside = binary->GetBufferPointer();
  const std::size_t count = level->GetBufferedRegion().GetNumberOfPixels();
  double sum_in = 0;  // ITK's sign convention: decide from the lumen voxels
  for (std::size_t i = 0; i < count; ++i)
    if (inside[i] > 0.5f) sum_in += phi[i];
  const float sign = sum_in >= 0 ? 0.5f : -0.5f;
  for (std::size_t i = 0; i < count; ++i) out[i] = 0.5f + sign * phi[i];
}

// The CT's air/tissue value of the padded crop's slices [k0, k1): 0.5 at air_tissue_hu, 1 at 500 HU
// below it (air), 0 at 500 HU above it (soft tissue); marks in `fl` the lumen voxels at or above
// fluid_hu (tagged fluid) and returns their count. Slices are independent (parallel_for chunks).
template <class Hu>
std::size_t ct_slices(const unsigned char* lumen, const CtVoxels& ct, const Hu* hu, const Box& box,
                      const ReconstructOptions& o, const std::array<std::size_t, 3>& n, std::size_t k0, std::size_t k1,
                      float* out, unsigned char* fl) {
  const auto ct_size = ct.image->GetBufferedRegion().GetSize();
  const long lo[3] = {long(box.lo[0]) - 1, long(box.lo[1]) - 1, long(box.lo[2]) - 1};  // padded crop origin
  std::size_t fluid_voxels = 0, idx = k0 * n[1] * n[0];
  for (std::size_t k = k0; k < k1; ++k)
    for (std::size_t j = 0; j < n[1]; ++j)
      for (std::size_t i = 0; i < n[0]; ++i, ++idx) {
        const long g[3] = {lo[0] + long(i), lo[1] + long(j), lo[2] + long(k)};
        bool in_ct = true;
        for (int a = 0; a < 3; ++a) in_ct = in_ct && g[a] >= 0 && g[a] < long(ct_size[a]);
        const float v = in_ct ? (float)hu[(std::size_t(g[2]) * ct_size[1] + std::size_t(g[1])) * ct_size[0] + std::size_t(g[0])]
                              : float(o.air_tissue_hu + 500.0);  // outside the scan: tissue
        out[idx] = float(0.5 + (o.air_tissue_hu - double(v)) / 1000.0);
        if (lumen[idx] && double(v) >= o.fluid_hu) fl[idx] = 1, ++fluid_voxels;
      }
  return fluid_voxels;
}

// Calls body(begin, end) on chunks of whole slices of an n-voxel image (parallel_for over the
// slices): every voxel is computed the same way whoever computes it; per-chunk counts are summed.
std::size_t for_slices(const std::array<std::size_t, 3>& n,
                       const std::function<std::size_t(std::size_t k0, std::size_t k1)>& body) {
  std::vector<std::size_t> counts(n[2], 0);  // by a chunk's first slice: chunks never share one
  parallel_for(n[2], [&](std::size_t k0, std::size_t k1) { counts[k0] = body(k0, k1); });
  std::size_t total = 0;
  for (std::size_t c : counts) total += c;
  return total;
}

// The CT field over the padded crop (ct_slices); NaN marks tagged fluid and its neighbourhood
// (2 voxels), where the mask field is used instead. Returns the fluid voxel count.
std::size_t ct_field(vtkImageData* binary, const CtVoxels& ct, const Box& box, const ReconstructOptions& o, float* out) {
  const auto n = dims_of(binary);
  const auto* lumen = static_cast<const unsigned char*>(binary->GetScalarPointer());
  std::vector<unsigned char> fluid(n[0] * n[1] * n[2], 0);
  unsigned char* fl = fluid.data();
  const std::size_t fluid_voxels = for_slices(
      n, [&](std::size_t k0, std::size_t k1) {  // a 16-bit HU gives the float it came from
        return ct.f ? ct_slices(lumen, ct, ct.f, box, o, n, k0, k1, out, fl) : ct_slices(lumen, ct, ct.s, box, o, n, k0, k1, out, fl);
      });
  if (!fluid_voxels) return 0;
  const int radius[3] = {2, 2, 2};  // the 5 x 5 x 5 box around each fluid voxel
  dilate_box(fl, n, radius);
  const unsigned char* near_fluid = fl;
  const std::size_t slice = n[0] * n[1];
  for_slices(n, [&](std::size_t k0, std::size_t k1) {
    for (std::size_t i = k0 * slice; i < k1 * slice; ++i)
      if (near_fluid[i]) out[i] = std::numeric_limits<float>::quiet_NaN();
    return std::size_t(0);
  });
  return fluid_voxels;
}

// The mask's own field where the CT is not used (everywhere without a CT, at the NaN voxels with
// one): Whitaker's, or the binary values (the staircase, smoothed on the mesh afterwards).
void mask_field(vtkImageData* binary, const std::array<double, 3>& spacing, const ReconstructOptions& o, bool use_ct,
                float* out) {
  const auto n = dims_of(binary);
  const auto* b = static_cast<const unsigned char*>(binary->GetScalarPointer());
  std::vector<float> smoothed;
  if (o.mask_smoothing == "antialias") {
    smoothed.resize(n[0] * n[1] * n[2]);
    antialias_field(to_itk_float(binary, spacing), o, smoothed.data());
  }
  const std::size_t slice = n[0] * n[1];
  for_slices(n, [&](std::size_t k0, std::size_t k1) {
    for (std::size_t i = k0 * slice; i < k1 * slice; ++i)
      if (!use_ct || std::isnan(out[i])) out[i] = smoothed.empty() ? float(b[i]) : smoothed[i];
    return std::size_t(0);
  });
}

// The constraint: each voxel on its side of 0.5, at least kFieldMargin from it. Returns the lumen
// voxels the field put outside (clamped).
std::size_t constrain(vtkImageData* binary, float* out) {
  const auto n = dims_of(binary);
  const auto* lumen = static_cast<const unsigned char*>(binary->GetScalarPointer());
  const std::size_t slice = n[0] * n[1];
  return for_slices(n, [&](std::size_t k0, std::size_t k1) {
    std::size_t clamped = 0;
    for (std::size_t i = k0 * slice; i < k1 * slice; ++i) {
      const float v = out[i];
      const float bounded = lumen[i] ? std::max(v, 0.5f + kFieldMargin) : std::min(v, 0.5f - kFieldMargin);
      clamped += lumen[i] && bounded != v;
      out[i] = bounded;
    }
    return clamped;
  });
}

}  // namespace

vtkSmartPointer<vtkImageData> subvoxel_field(vtkImageData* binary, const CtVoxels& ct, const Box& box,
                                             const std::array<double, 3>& spacing, const ReconstructOptions& o,
                                             ReconstructStats& st) {
  Stopwatch watch;
  auto field = vtkSmartPointer<vtkImageData>::New();
  field->SetDimensions(binary->GetDimensions());
  field->SetOrigin(binary->GetOrigin());
  field->SetSpacing(1, 1, 1);
  field->AllocateScalars(VTK_FLOAT, 1);
  float* out = static_cast<float*>(field->GetScalarPointer());
  const bool use_ct = ct && o.subvoxel != "mask";
  if (use_ct) {
    st.fluid_voxels = ct_field(binary, ct, box, o, out);
    st.field_source = "ct";
  }
  if (!use_ct || st.fluid_voxels) {
    // The mask's own field where the CT is not used: Whitaker's, or the binary values (the
    // staircase, smoothed on the mesh afterwards).
    mask_field(binary, spacing, o, use_ct, out);
    if (!use_ct) st.field_source = "mask (" + o.mask_smoothing + ")";
  }
  st.field_clamped_voxels = constrain(binary, out);
  st.time_field_s = watch.seconds();
  return field;
}

}  // namespace cf::reconstruct_detail
