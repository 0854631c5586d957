#pragma once
// Flat test disks for the patch-slit and disk-map tests: a strip of grid vertices and a stadium cut from it.
#include <algorithm>
#include <cmath>
#include <vector>

#include "../src/flatten_internal.h"
#include "squeezed_grid.h"

namespace cf::test_shapes {

// A flat strip of nx x ny vertices, 1 mm apart (a disk: one boundary loop), vertex j * nx + i at (i, j, 0).
inline flat_detail::Surface strip(int nx, int ny) {
  flat_detail::Surface s;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) s.p.emplace_back(i, j, 0.0), s.src.push_back(j * nx + i);
  grid_triangles(nx, ny, s.t);
  return s;
}

// A 12 mm wide stadium: the faces of strip(nx, 13) whose centroid lies within 6 mm of the segment y = 6,
// x in [6, nx - 7] (round ends), cleaned into a disk (nx = 121: 12 x 120 mm).
inline flat_detail::Surface stadium(int nx) {
  const flat_detail::Surface s = strip(nx, 13);
  std::vector<char> keep(s.t.size(), 0);
  for (std::size_t f = 0; f < s.t.size(); ++f) {
    const flat_detail::V3 c =
        (s.p[std::size_t(s.t[f][0])] + s.p[std::size_t(s.t[f][1])] + s.p[std::size_t(s.t[f][2])]) / 3.0;
    const double x = std::clamp(c.x(), 6.0, nx - 7.0);
    keep[f] = std::hypot(c.x() - x, c.y() - 6.0) <= 6.0;
  }
  flat_detail::clean_selection(s, flat_detail::build_edges(s.t), keep);
  return flat_detail::sub_surface(s, keep);
}

}  // namespace cf::test_shapes
