// The sub-voxel field the surface is extracted from (docs/reconstruct.md, "Sub-voxel surface").
// Every variant ends with the same constraint: the field is > 0.5 exactly at lumen voxels, so the
// isosurface keeps the binary mask's triangles and each vertex stays on its lattice edge, strictly
// between the centres of the lumen voxel and the background voxel it separates (< 1/2 voxel from
// the raw staircase surface).
#include <itkAntiAliasBinaryImageFilter.h>
#include <itkBinaryDilateImageFilter.h>
#include <itkFlatStructuringElement.h>
#include <itkImage.h>
#include <vtkNew.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "colonflat/core/error.h"
#include "colonflat/core/run_stats.h"
#include "reconstruct_internal.h"

namespace cf::reconstruct_detail {
namespace {

using FloatImage = itk::Image<float, 3>;
using LabelImage = itk::Image<unsigned char, 3>;

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

// The CT's air/tissue field over the padded crop: 0.5 at air_tissue_hu, 1 at 500 HU below it
// (air), 0 at 500 HU above it (soft tissue); NaN marks tagged fluid (lumen voxels at or above
// fluid_hu) and their neighbourhood (2 voxels), where the mask field is used instead.
std::size_t ct_field(vtkImageData* binary, const CtImage* ct, const Box& box, const ReconstructOptions& o, float* out) {
  const auto n = dims_of(binary);
  const auto ct_size = ct->GetBufferedRegion().GetSize();
  const long lo[3] = {long(box.lo[0]) - 1, long(box.lo[1]) - 1, long(box.lo[2]) - 1};  // padded crop origin
  const float* hu = ct->GetBufferPointer();
  const auto* lumen = static_cast<const unsigned char*>(binary->GetScalarPointer());
  auto fluid = LabelImage::New();
  LabelImage::RegionType region;
  for (int a = 0; a < 3; ++a) region.SetSize(a, n[a]);
  fluid->SetRegions(region);
  fluid->Allocate(true);
  unsigned char* fl = fluid->GetBufferPointer();
  std::size_t fluid_voxels = 0, idx = 0;
  for (std::size_t k = 0; k < n[2]; ++k)
    for (std::size_t j = 0; j < n[1]; ++j)
      for (std::size_t i = 0; i < n[0]; ++i, ++idx) {
        const long g[3] = {lo[0] + long(i), lo[1] + long(j), lo[2] + long(k)};
        bool in_ct = true;
        for (int a = 0; a < 3; ++a) in_ct = in_ct && g[a] >= 0 && g[a] < long(ct_size[a]);
        const float v = in_ct ? hu[(std::size_t(g[2]) * ct_size[1] + std::size_t(g[1])) * ct_size[0] + std::size_t(g[0])]
                              : float(o.air_tissue_hu + 500.0);  // outside the scan: tissue
        out[idx] = float(0.5 + (o.air_tissue_hu - double(v)) / 1000.0);
        if (lumen[idx] && double(v) >= o.fluid_hu) fl[idx] = 1, ++fluid_voxels;
      }
  if (!fluid_voxels) return 0;
  using Element = itk::FlatStructuringElement<3>;
  Element::RadiusType radius;
  radius.Fill(2);
  using Dilate = itk::BinaryDilateImageFilter<LabelImage, LabelImage, Element>;
  auto dilate = Dilate::New();
  dilate->SetInput(fluid);
  dilate->SetKernel(Element::Box(radius));
  dilate->SetForegroundValue(1);
  dilate->Update();
  const unsigned char* near_fluid = dilate->GetOutput()->GetBufferPointer();
  for (std::size_t i = 0; i < n[0] * n[1] * n[2]; ++i)
    if (near_fluid[i]) out[i] = std::numeric_limits<float>::quiet_NaN();
  return fluid_voxels;
}

}  // namespace

vtkSmartPointer<vtkImageData> subvoxel_field(vtkImageData* binary, const CtImage* ct, const Box& box,
                                             const std::array<double, 3>& spacing, const ReconstructOptions& o,
                                             ReconstructStats& st) {
  Stopwatch watch;
  const auto n = dims_of(binary);
  const std::size_t count = n[0] * n[1] * n[2];
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
    std::vector<float> mask_values(count);
    if (o.mask_smoothing == "antialias") {
      antialias_field(to_itk_float(binary, spacing), o, mask_values.data());
    } else {
      const auto* b = static_cast<const unsigned char*>(binary->GetScalarPointer());
      for (std::size_t i = 0; i < count; ++i) mask_values[i] = float(b[i]);
    }
    if (!use_ct) st.field_source = "mask (" + o.mask_smoothing + ")";
    for (std::size_t i = 0; i < count; ++i)
      if (!use_ct || std::isnan(out[i])) out[i] = mask_values[i];
  }
  // The constraint: each voxel on its side of 0.5, at least kFieldMargin from it.
  const auto* lumen = static_cast<const unsigned char*>(binary->GetScalarPointer());
  std::size_t clamped = 0;
  for (std::size_t i = 0; i < count; ++i) {
    const float v = out[i];
    const float bounded = lumen[i] ? std::max(v, 0.5f + kFieldMargin) : std::min(v, 0.5f - kFieldMargin);
    clamped += lumen[i] && bounded != v;  // lumen voxels the field put outside
    out[i] = bounded;
  }
  st.field_clamped_voxels = clamped;
  st.time_field_s = watch.seconds();
  return field;
}

}  // namespace cf::reconstruct_detail
