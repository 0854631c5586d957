#include "colonflat/core/vertex_corners.h"

#include "colonflat/core/huge_pages.h"
namespace cf {

VertexCorners vertex_corners(const std::vector<std::array<int, 3>>& triangles, std::size_t n_vertices) {
  VertexCorners vc;
  assign_huge(vc.start, n_vertices + 1, 0u);
  for (const auto& t : triangles)
    for (int v : t) ++vc.start[static_cast<std::size_t>(v) + 1];
  for (std::size_t v = 0; v < n_vertices; ++v) vc.start[v + 1] += vc.start[v];
  resize_huge(vc.corner, 3 * triangles.size());
  // Fill through start[v] (moved one bucket along), then shift it back: no second cursor array.
  for (std::size_t f = 0; f < triangles.size(); ++f)
    for (std::uint32_t k = 0; k < 3; ++k)
      vc.corner[vc.start[triangles[f][k]]++] = static_cast<std::uint32_t>(3 * f + k);
  for (std::size_t v = n_vertices; v > 0; --v) vc.start[v] = vc.start[v - 1];
  vc.start[0] = 0;
  return vc;
}

}  // namespace cf
