#pragma once
// Internal pieces of the reconstruct module shared by its source files (not installed API).
//   mask_grid.cpp     crop/pad of the mask, (6,18) Euler count, isosurface, index -> LPS
//   subvoxel.cpp      the sub-voxel field the isosurface is taken from (smoothed mask or CT)
//   reconstruct.cpp   the stage's steps (SurfaceReconstruction)
#include <vtkImageData.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "colonflat/core/soup.h"
#include "colonflat/core/voxel_box.h"
#include "colonflat/reconstruct/reconstruct.h"

namespace cf::reconstruct_detail {

// Inclusive bounding box of the lumen in buffer indices, and its voxel count (nonzero_box of the
// mask buffer: any non-zero voxel is lumen).
using Box = VoxelBox;

// The cropped lumen, binarised (0/1), with `pad` voxels of background on every side, as VTK
// image data in index space (origin = buffer index of its first voxel, spacing 1).
vtkSmartPointer<vtkImageData> padded_crop(const unsigned char* d, const std::array<std::size_t, 3>& n, const Box& b,
                                          int pad = 1);

// Euler characteristic of a 0/1 volume (x fastest) whose last slice in each direction is
// background, in the (6,18) topology (see mask_euler_characteristic_6_18).
long long euler_6_18(const unsigned char* d, std::size_t nx, std::size_t ny, std::size_t nz);

// The isosurface at 0.5 of `img` (unsigned char 0/1, or float in [0, 1] for the sub-voxel field)
// with the named VTK filter. discrete-flying-edges takes label 1 and needs a 0/1 image.
vtkSmartPointer<vtkPolyData> isosurface(vtkImageData* img, const std::string& method);

// Index -> LPS mm: p = origin + direction * diag(spacing) * index (ITK's convention; the region
// start is folded into the origin).
struct IndexToLps {
  double m[3][3], o[3];
  std::array<double, 3> operator()(const double* x) const {
    std::array<double, 3> p;
    for (int r = 0; r < 3; ++r) p[r] = o[r] + m[r][0] * x[0] + m[r][1] * x[1] + m[r][2] * x[2];
    return p;
  }
};

// Points mapped to LPS; triangles reversed when the map reverses orientation (flip).
TriangleList to_lps(vtkPolyData* pd, const IndexToLps& map, bool flip);

// The staircase position of each isosurface point (the midpoint of the lattice edge it lies on),
// mapped to LPS: the point of the binary mask's surface that a sub-voxel point came from.
std::vector<std::array<double, 3>> staircase_positions(vtkPolyData* pd, const IndexToLps& map);

// The sub-voxel field of the padded crop `binary` (0/1 unsigned char, index space, as made by
// padded_crop): a float image in [0, 1] whose value is > 0.5 exactly at lumen voxels (|v - 0.5|
// >= kFieldMargin), so that its 0.5 isosurface has the binary mask's marching-cubes triangles and
// each vertex stays on the lattice edge of the raw surface, strictly between the two voxel
// centres. `ct` (may be null) must share the mask's grid; `box` gives the crop's buffer offset.
// spacing: voxel size in mm along each index axis. Fills the field statistics of `stats`.
constexpr float kFieldMargin = 0.02f;
// The CT as reconstruct reads it: its geometry and its HU as float or in 16 bits (one of them).
struct CtVoxels {
  const itk::ImageBase<3>* image = nullptr;  // null: no CT
  const float* f = nullptr;
  const short* s = nullptr;
  explicit operator bool() const { return image != nullptr; }
};
vtkSmartPointer<vtkImageData> subvoxel_field(vtkImageData* binary, const CtVoxels& ct, const Box& box,
                                             const std::array<double, 3>& spacing, const ReconstructOptions& options,
                                             ReconstructStats& stats);

}  // namespace cf::reconstruct_detail
