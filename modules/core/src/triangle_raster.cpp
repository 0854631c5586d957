#include "colonflat/core/triangle_raster.h"

#include <algorithm>
#include <cmath>

#include "colonflat/core/threads.h"

namespace cf {
namespace {

using Corners = std::array<std::array<double, 2>, 3>;

// Relative slack of the inside test: a centre on a shared edge, where rounding can make one
// weight -1e-16, still counts for both triangles (no pixel falls between two neighbours).
constexpr double kEdgeSlack = 1e-12;

// The rows [j0, j1) of the pixels whose centres can lie in triangle c (its bounding box).
struct PixelBox {
  int i0, i1, j0, j1;  // half-open
};

PixelBox pixel_box(const RasterGrid& g, const Corners& c, int row0, int row1) {
  const double xmin = std::min({c[0][0], c[1][0], c[2][0]}), xmax = std::max({c[0][0], c[1][0], c[2][0]});
  const double ymin = std::min({c[0][1], c[1][1], c[2][1]}), ymax = std::max({c[0][1], c[1][1], c[2][1]});
  PixelBox b;
  b.i0 = std::max(0, int(std::ceil((xmin - g.x0) / g.spacing - kEdgeSlack)));
  b.i1 = std::min(g.width, int(std::floor((xmax - g.x0) / g.spacing + kEdgeSlack)) + 1);
  b.j0 = std::max(row0, int(std::ceil((ymin - g.y0) / g.spacing - kEdgeSlack)));
  b.j1 = std::min(row1, int(std::floor((ymax - g.y0) / g.spacing + kEdgeSlack)) + 1);
  return b;
}

// Writes triangle t into the pixels of rows [row0, row1) whose centres it covers.
void rasterise_one(const RasterGrid& g, std::size_t t, const Corners& c, int row0, int row1,
                   std::vector<RasterHit>& hits) {
  const double area2 = (c[1][0] - c[0][0]) * (c[2][1] - c[0][1]) - (c[1][1] - c[0][1]) * (c[2][0] - c[0][0]);
  if (area2 == 0 || !std::isfinite(area2)) return;
  const PixelBox b = pixel_box(g, c, row0, row1);
  for (int j = b.j0; j < b.j1; ++j) {
    const double y = g.y0 + j * g.spacing;
    for (int i = b.i0; i < b.i1; ++i) {
      const double x = g.x0 + i * g.spacing;
      std::array<double, 3> w;
      for (int k = 0; k < 3; ++k) {
        const auto& p = c[(k + 1) % 3];
        const auto& q = c[(k + 2) % 3];
        w[k] = ((q[0] - p[0]) * (y - p[1]) - (q[1] - p[1]) * (x - p[0])) / area2;
      }
      if (w[0] < -kEdgeSlack || w[1] < -kEdgeSlack || w[2] < -kEdgeSlack) continue;
      hits[std::size_t(j) * g.width + i] = {int(t), w};
    }
  }
}

}  // namespace

std::vector<RasterHit> rasterise_triangles(const RasterGrid& g, std::size_t count, const TriangleCorners& corners) {
  std::vector<RasterHit> hits(std::size_t(std::max(0, g.width)) * std::max(0, g.height));
  if (hits.empty()) return hits;
  const std::size_t chunks = std::size_t(std::max(1, std::min(thread_count(), g.height)));
  parallel_for(chunks, [&](std::size_t c0, std::size_t c1) {
    for (std::size_t c = c0; c < c1; ++c) {
      const int row0 = int(g.height * c / chunks), row1 = int(g.height * (c + 1) / chunks);
      for (std::size_t t = 0; t < count; ++t) rasterise_one(g, t, corners(t), row0, row1, hits);
    }
  });
  return hits;
}

}  // namespace cf
