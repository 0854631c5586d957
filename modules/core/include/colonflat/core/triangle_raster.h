#pragma once
// Pixel-centre rasterisation of 2D triangles onto a regular grid: for every pixel, the triangle
// that covers its centre and the centre's barycentric weights in it. What a probe filter gives on
// an image grid, in O(pixels + triangles) instead of one point location per pixel.
#include <array>
#include <cstddef>
#include <functional>
#include <vector>

namespace cf {

// A width x height grid; pixel (i, j) has its centre at (x0 + i * spacing, y0 + j * spacing).
// Pixel ids count rows first: id = j * width + i.
struct RasterGrid {
  double x0 = 0, y0 = 0;  // centre of pixel (0, 0)
  double spacing = 1;     // > 0, the same unit as the triangles' corners
  int width = 0, height = 0;
};

// One pixel's result: `triangle` < 0 where no triangle covers the centre; else the triangle's
// index and the centre's barycentric weights (>= 0 up to rounding, summing to 1) at its corners.
struct RasterHit {
  int triangle = -1;
  std::array<double, 3> weight{0, 0, 0};
};

// The corners of triangle t, in the grid's coordinates (either orientation).
using TriangleCorners = std::function<std::array<std::array<double, 2>, 3>(std::size_t t)>;

// grid: width, height >= 0, spacing > 0. triangles: corners(t) for t in [0, count).
// Returns width * height hits. A centre on an edge or a corner counts as covered by every
// triangle sharing it; where several triangles cover a centre, the one with the highest index
// wins (so the result is a function of the triangle order only). Degenerate (zero-area)
// triangles cover nothing. Rows are split over cf::thread_count() threads; every pixel is
// computed by one thread in triangle order, so the result is the same for any count.
std::vector<RasterHit> rasterise_triangles(const RasterGrid& grid, std::size_t count, const TriangleCorners& corners);

}  // namespace cf
