#pragma once
// CT views for the report: axial, coronal and sagittal planes through an LPS point, sampled with
// trilinear interpolation in patient space (any volume direction), shown in radiological
// convention (patient right on the viewer's left; axial viewed from the feet, anterior up;
// coronal and sagittal with superior up, sagittal with anterior on the left), windowed to 8-bit
// grey PNGs.
#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colonflat/volume/volume_io.h"

namespace cf {

enum class Plane { axial, coronal, sagittal };
const char* plane_name(Plane p);  // "axial", "coronal", "sagittal"

struct CtWindow {
  std::string name;  // "lung", "soft tissue"
  double level = 0, width = 1;  // HU
};
const CtWindow& lung_window();         // L -200 / W 1500 (CT colonography 2D reading)
const CtWindow& soft_tissue_window();  // L 40 / W 400
const CtWindow& mask_window();         // L 0.5 / W 1: a 0/1 lumen mask, lumen white

// On-screen axes of a plane: LPS axis index and sign of the screen's right (u) and down (v)
// directions, and the LPS axis fixed by the plane (its normal).
struct PlaneAxes {
  int u_axis, u_sign, v_axis, v_sign, fixed_axis;
};
PlaneAxes plane_axes(Plane p);

// HU values of a plane: `w` x `h` pixels of `pixel_mm`, row-major from the top, pixel (0, 0)'s
// centre at screen coordinates (u0, v0) mm (u = u_sign * LPS[u_axis], ...), at LPS[fixed_axis] =
// `fixed`. Outside the volume: -2000.
struct PlaneImage {
  Plane plane = Plane::axial;
  int w = 0, h = 0;
  double pixel_mm = 1, u0 = 0, v0 = 0, fixed = 0;
  std::vector<float> hu;
};
template <class Image>  // CtImage or CompactCtImage (HU), or MaskImage (0/1, a run without a CT)
PlaneImage sample_plane(const Image* ct, Plane plane, double fixed, double u0, double v0, int w, int h,
                        double pixel_mm);
// A square plane of side `fov_mm` centred on `lps`.
template <class Image>
PlaneImage sample_plane_around(const Image* ct, Plane plane, const std::array<double, 3>& lps, double fov_mm,
                               int pixels);

// 8-bit grey value of `hu` through `window` (0 below, 255 above).
unsigned char window_grey(float hu, const CtWindow& window);
// w x h pixels of `components` (1 grey, 3 RGB) bytes each, rows from the top, encoded as a PNG
// (its bytes).
std::string encode_png(int w, int h, int components, const std::vector<unsigned char>& pixels);
// Writes w x h pixels of `components` (1 grey, 3 RGB) bytes each, rows from the top, as a PNG (atomic).
void write_png_pixels(int w, int h, int components, const std::vector<unsigned char>& pixels,
                      const std::filesystem::path& path);
// Writes `image` through `window` as an 8-bit grey PNG (atomic).
void write_windowed_png(const PlaneImage& image, const CtWindow& window, const std::filesystem::path& path);

// Evenly spaced parallel planes through a box (LPS mm), each written as a PNG
// `<dir>/<prefix><plane>_<n>.png`. The JSON describes them for the page: {plane, u_axis, u_sign,
// v_axis, v_sign, fixed_axis, u0, v0, pixel_mm, w, h, positions: [mm], files: [relative paths]}.
struct SliceStackOptions {
  double step_mm = 5;      // between planes
  double pixel_mm = 1;     // in-plane pixel size
  double margin_mm = 25;   // added around the box
  const CtWindow* window = nullptr;  // null: lung window
};
template <class Image>
nlohmann::json write_slice_stack(const Image* ct, Plane plane, const std::array<double, 3>& box_min,
                                 const std::array<double, 3>& box_max, const SliceStackOptions& opts,
                                 const std::filesystem::path& dir, const std::string& rel_prefix);

// write_slice_stack in two steps: the planes sampled and encoded in memory (the volume is only
// read during the call), then written as the same files with the same JSON.
struct DrawnSliceStack {
  nlohmann::json json;                           // write_slice_stack's, "files" still empty
  std::vector<std::string> names;                // "<plane>_<n>.png", one per position
  std::vector<std::string> pngs;                 // each plane's PNG bytes
};
template <class Image>
DrawnSliceStack draw_slice_stack(const Image* ct, Plane plane, const std::array<double, 3>& box_min,
                                 const std::array<double, 3>& box_max, const SliceStackOptions& opts);
nlohmann::json write_drawn_stack(const DrawnSliceStack& stack, const std::filesystem::path& dir,
                                 const std::string& rel_prefix);

// The axial, coronal and sagittal stacks through one box, drawn ahead (the run draws them beside
// the stages); the report writes them when its own box and options are these.
struct DrawnPlaneStacks {
  std::array<double, 3> box_min{}, box_max{};
  double step_mm = 0, pixel_mm = 0;
  std::vector<DrawnSliceStack> planes;  // axial, coronal, sagittal
};
DrawnPlaneStacks draw_plane_stacks(const CtImage* ct, const std::array<double, 3>& box_min,
                                   const std::array<double, 3>& box_max, const SliceStackOptions& opts);
// The same from the CT in 16 bits (`colonflat run` holds it so from segment's crop on): the same pixels.
DrawnPlaneStacks draw_plane_stacks(const CompactCtImage* ct, const std::array<double, 3>& box_min,
                                   const std::array<double, 3>& box_max, const SliceStackOptions& opts);

// The LPS box of the centres of the non-zero voxels of `mask` (any direction: the corners of their
// index box mapped to LPS); false when every voxel is zero.
bool mask_box_lps(const MaskImage& mask, std::array<double, 3>& box_min, std::array<double, 3>& box_max);

// The volume's geometry for the page: size, spacing, origin, direction and the 3x3 matrix taking
// (LPS - origin) to continuous voxel indices.
template <class Image>
nlohmann::json ct_geometry_json(const Image* ct);

}  // namespace cf
