#include "colonflat/report/ct_views.h"

#include <itkLinearInterpolateImageFunction.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkUnsignedCharArray.h>

#include <algorithm>
#include <cmath>

#include "colonflat/core/atomic_file.h"
#include "colonflat/core/error.h"
#include "colonflat/core/threads.h"
#include "colonflat/core/voxel_box.h"
#include "colonflat/core/vtk_messages.h"

namespace fs = std::filesystem;

namespace cf {

const char* plane_name(Plane p) {
  switch (p) {
    case Plane::axial: return "axial";
    case Plane::coronal: return "coronal";
    default: return "sagittal";
  }
}

const CtWindow& lung_window() {
  static const CtWindow w{"lung", -200, 1500};
  return w;
}

const CtWindow& soft_tissue_window() {
  static const CtWindow w{"soft tissue", 40, 400};
  return w;
}

const CtWindow& mask_window() {
  static const CtWindow w{"mask", 0.5, 1};
  return w;
}

PlaneAxes plane_axes(Plane p) {
  // LPS: +x left, +y posterior, +z superior. Screen right = patient left (+x) or posterior (+y,
  // sagittal); screen down = posterior (+y, axial) or inferior (-z).
  switch (p) {
    case Plane::axial: return {0, +1, 1, +1, 2};
    case Plane::coronal: return {0, +1, 2, -1, 1};
    default: return {1, +1, 2, -1, 0};
  }
}

template <class Image>
PlaneImage sample_plane(const Image* ct, Plane plane, double fixed, double u0, double v0, int w, int h,
                        double pixel_mm) {
  if (!ct) throw Error("sample_plane: no CT volume");
  PlaneImage out;
  out.plane = plane;
  out.w = w, out.h = h, out.pixel_mm = pixel_mm, out.u0 = u0, out.v0 = v0, out.fixed = fixed;
  out.hu.assign(std::size_t(w) * h, -2000.0f);
  using Interp = itk::LinearInterpolateImageFunction<Image, double>;
  auto interp = Interp::New();
  interp->SetInputImage(ct);
  const PlaneAxes a = plane_axes(plane);
  // The index is affine in the pixel: per row, the start index and a per-column step.
  const auto index_of = [&](int r, int c) {
    typename Interp::PointType p;
    p[a.fixed_axis] = fixed;
    p[a.v_axis] = a.v_sign * (v0 + r * pixel_mm);
    p[a.u_axis] = a.u_sign * (u0 + c * pixel_mm);
    typename Interp::ContinuousIndexType idx;
    ct->TransformPhysicalPointToContinuousIndex(p, idx);
    return idx;
  };
  for (int r = 0; r < h; ++r) {
    const auto start = index_of(r, 0), next = index_of(r, 1);
    typename Interp::ContinuousIndexType idx;
    for (int c = 0; c < w; ++c) {
      for (int k = 0; k < 3; ++k) idx[k] = start[k] + c * (next[k] - start[k]);
      if (interp->IsInsideBuffer(idx)) out.hu[std::size_t(r) * w + c] = float(interp->EvaluateAtContinuousIndex(idx));
    }
  }
  return out;
}

template <class Image>
PlaneImage sample_plane_around(const Image* ct, Plane plane, const std::array<double, 3>& lps, double fov_mm,
                               int pixels) {
  const PlaneAxes a = plane_axes(plane);
  const double pix = fov_mm / pixels;
  const double u_c = a.u_sign * lps[a.u_axis], v_c = a.v_sign * lps[a.v_axis];
  // pixel centres symmetric about the point: its position is the image centre
  const double u0 = u_c - 0.5 * (pixels - 1) * pix, v0 = v_c - 0.5 * (pixels - 1) * pix;
  return sample_plane(ct, plane, lps[a.fixed_axis], u0, v0, pixels, pixels, pix);
}

std::string encode_png(int w, int h, int components, const std::vector<unsigned char>& pixels) {
  if (pixels.size() != std::size_t(w) * h * components) throw Error("PNG pixel count does not match its size");
  vtkNew<vtkImageData> img;
  img->SetDimensions(w, h, 1);
  img->AllocateScalars(VTK_UNSIGNED_CHAR, components);
  auto* px = static_cast<unsigned char*>(img->GetScalarPointer());
  const std::size_t row = std::size_t(w) * components;
  for (int r = 0; r < h; ++r) std::copy_n(pixels.data() + r * row, row, px + std::size_t(h - 1 - r) * row);  // VTK rows count from the bottom
  vtkNew<vtkPNGWriter> writer;
  writer->SetInputData(img);
  writer->WriteToMemoryOn();
  writer->SetCompressionLevel(1);  // fast; these images are small
  VtkMessageCapture msgs;
  writer->Write();
  vtkUnsignedCharArray* out = writer->GetResult();
  if (writer->GetErrorCode() != 0 || !msgs.errors().empty() || !out)
    throw Error("cannot encode a PNG: " + (msgs.errors().empty() ? std::string("VTK's PNG writer failed") : msgs.errors().front()));
  const auto* b = reinterpret_cast<const char*>(out->GetPointer(0));
  return std::string(b, b + out->GetNumberOfValues());
}

void write_png_pixels(int w, int h, int components, const std::vector<unsigned char>& pixels, const fs::path& path) {
  if (pixels.size() != std::size_t(w) * h * components) throw Error(path.string() + ": PNG pixel count does not match its size");
  write_text_atomically(path, encode_png(w, h, components, pixels));
}

unsigned char window_grey(float hu, const CtWindow& win) {
  const double v = (hu - (win.level - 0.5 * win.width)) / win.width;
  return static_cast<unsigned char>(std::lround(255 * std::clamp(v, 0.0, 1.0)));
}

namespace {
std::string windowed_png(const PlaneImage& im, const CtWindow& win) {
  std::vector<unsigned char> grey(im.hu.size());
  std::transform(im.hu.begin(), im.hu.end(), grey.begin(), [&](float v) { return window_grey(v, win); });
  return encode_png(im.w, im.h, 1, grey);
}
}  // namespace

template <class Image>
DrawnSliceStack draw_slice_stack(const Image* ct, Plane plane, const std::array<double, 3>& box_min,
                                 const std::array<double, 3>& box_max, const SliceStackOptions& o) {
  const PlaneAxes a = plane_axes(plane);
  auto screen_range = [&](int axis, int sign) {
    const double lo = sign * box_min[axis], hi = sign * box_max[axis];
    return std::array<double, 2>{std::min(lo, hi) - o.margin_mm, std::max(lo, hi) + o.margin_mm};
  };
  const auto ur = screen_range(a.u_axis, a.u_sign), vr = screen_range(a.v_axis, a.v_sign);
  const int w = std::max(1, int(std::ceil((ur[1] - ur[0]) / o.pixel_mm)));
  const int h = std::max(1, int(std::ceil((vr[1] - vr[0]) / o.pixel_mm)));
  const double f0 = box_min[a.fixed_axis], f1 = box_max[a.fixed_axis];
  const int n = std::max(1, int(std::floor((f1 - f0) / o.step_mm)) + 1);
  DrawnSliceStack d;
  d.json = {{"plane", plane_name(plane)}, {"u_axis", a.u_axis}, {"u_sign", a.u_sign},
            {"v_axis", a.v_axis}, {"v_sign", a.v_sign}, {"fixed_axis", a.fixed_axis},
            {"u0", ur[0]}, {"v0", vr[0]}, {"pixel_mm", o.pixel_mm}, {"w", w}, {"h", h},
            {"positions", nlohmann::json::array()}, {"files", nlohmann::json::array()}};
  auto fixed_of = [&](int i) { return f0 + 0.5 * ((f1 - f0) - (n - 1) * o.step_mm) + i * o.step_mm; };
  const CtWindow& window = o.window ? *o.window : lung_window();
  d.pngs.resize(std::size_t(n));
  // Each plane is sampled and encoded on the threads (a VtkMessageCapture collects its own
  // thread's messages); the list is made in order here.
  parallel_for(std::size_t(n), [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i)
      d.pngs[i] = windowed_png(sample_plane(ct, plane, fixed_of(int(i)), ur[0], vr[0], w, h, o.pixel_mm), window);
  });
  for (int i = 0; i < n; ++i) {
    d.json["positions"].push_back(std::round(fixed_of(i) * 100) / 100);
    d.names.push_back(std::string(plane_name(plane)) + "_" + std::to_string(i) + ".png");
  }
  return d;
}

void write_windowed_png(const PlaneImage& im, const CtWindow& win, const fs::path& path) {
  write_text_atomically(path, windowed_png(im, win));
}

nlohmann::json write_drawn_stack(const DrawnSliceStack& d, const fs::path& dir, const std::string& rel_prefix) {
  nlohmann::json j = d.json;
  parallel_for(d.pngs.size(), [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) write_text_atomically(dir / d.names[i], d.pngs[i]);
  });
  for (const std::string& name : d.names) j["files"].push_back(rel_prefix + name);
  return j;
}

template <class Image>
nlohmann::json write_slice_stack(const Image* ct, Plane plane, const std::array<double, 3>& box_min,
                                 const std::array<double, 3>& box_max, const SliceStackOptions& o,
                                 const fs::path& dir, const std::string& rel_prefix) {
  return write_drawn_stack(draw_slice_stack(ct, plane, box_min, box_max, o), dir, rel_prefix);
}

namespace {
template <class Image>
DrawnPlaneStacks plane_stacks(const Image* ct, const std::array<double, 3>& box_min,
                              const std::array<double, 3>& box_max, const SliceStackOptions& o) {
  DrawnPlaneStacks s;
  s.box_min = box_min, s.box_max = box_max, s.step_mm = o.step_mm, s.pixel_mm = o.pixel_mm;
  for (Plane p : {Plane::axial, Plane::coronal, Plane::sagittal}) s.planes.push_back(draw_slice_stack(ct, p, box_min, box_max, o));
  return s;
}
}  // namespace

DrawnPlaneStacks draw_plane_stacks(const CtImage* ct, const std::array<double, 3>& box_min,
                                   const std::array<double, 3>& box_max, const SliceStackOptions& o) {
  return plane_stacks(ct, box_min, box_max, o);
}

DrawnPlaneStacks draw_plane_stacks(const CompactCtImage* ct, const std::array<double, 3>& box_min,
                                   const std::array<double, 3>& box_max, const SliceStackOptions& o) {
  return plane_stacks(ct, box_min, box_max, o);
}

bool mask_box_lps(const MaskImage& mask, std::array<double, 3>& box_min, std::array<double, 3>& box_max) {
  const auto size = mask.GetLargestPossibleRegion().GetSize();
  const VoxelBox b = nonzero_box(mask.GetBufferPointer(), {size[0], size[1], size[2]});
  if (!b.count) return false;
  box_min = {1e300, 1e300, 1e300}, box_max = {-1e300, -1e300, -1e300};
  for (int corner = 0; corner < 8; ++corner) {
    MaskImage::IndexType idx;
    for (int a = 0; a < 3; ++a) idx[a] = itk::IndexValueType((corner >> a) & 1 ? b.hi[a] : b.lo[a]);
    MaskImage::PointType p;
    mask.TransformIndexToPhysicalPoint(idx, p);
    for (int a = 0; a < 3; ++a) box_min[a] = std::min(box_min[a], p[a]), box_max[a] = std::max(box_max[a], p[a]);
  }
  return true;
}

template <class Image>
nlohmann::json ct_geometry_json(const Image* ct) {
  const auto region = ct->GetLargestPossibleRegion();
  const auto sp = ct->GetSpacing();
  const auto org = ct->GetOrigin();
  const auto dir = ct->GetDirection();
  const auto inv = ct->GetInverseDirection();
  nlohmann::json to_index = nlohmann::json::array(), direction = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) {
    nlohmann::json row = nlohmann::json::array(), drow = nlohmann::json::array();
    for (int c = 0; c < 3; ++c) row.push_back(inv[r][c] / sp[r]), drow.push_back(dir[r][c]);
    to_index.push_back(row);
    direction.push_back(drow);
  }
  return {{"size", {region.GetSize()[0], region.GetSize()[1], region.GetSize()[2]}},
          {"spacing_mm", {sp[0], sp[1], sp[2]}},
          {"origin_lps_mm", {org[0], org[1], org[2]}},
          {"direction", direction},
          {"lps_to_index", to_index}};
}

// The two volume kinds a report shows.
#define CF_VIEW_VOLUME(Image)                                                                                     \
  template PlaneImage sample_plane(const Image*, Plane, double, double, double, int, int, double);             \
  template PlaneImage sample_plane_around(const Image*, Plane, const std::array<double, 3>&, double, int);       \
  template DrawnSliceStack draw_slice_stack(const Image*, Plane, const std::array<double, 3>&,                  \
                                            const std::array<double, 3>&, const SliceStackOptions&);            \
  template nlohmann::json write_slice_stack(const Image*, Plane, const std::array<double, 3>&,                  \
                                            const std::array<double, 3>&, const SliceStackOptions&,             \
                                            const fs::path&, const std::string&);                               \
  template nlohmann::json ct_geometry_json(const Image*);
CF_VIEW_VOLUME(CtImage)
CF_VIEW_VOLUME(CompactCtImage)
CF_VIEW_VOLUME(MaskImage)
#undef CF_VIEW_VOLUME

}  // namespace cf
