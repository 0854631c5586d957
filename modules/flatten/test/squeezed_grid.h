#pragma once
// A flat 24 x 12 grid (z = 0, 1 mm spacing; or k times as many vertices each way) whose map squeezes the middle 8 (8 k) columns to `squeeze` of
// their width, its ends and rims fixed: a tiny band for the area correction and balancing tests.
#include <algorithm>

#include "../src/flatten_internal.h"

namespace cf::test_shapes {

// Two triangles per cell of an nx x ny vertex grid numbered row by row (v = j * nx + i), both
// counter-clockwise seen from +z, appended to `t`.
inline void grid_triangles(int nx, int ny, std::vector<flat_detail::Tri>& t) {
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      const int v = j * nx + i;
      t.push_back({v, v + 1, v + nx + 1});
      t.push_back({v, v + nx + 1, v + nx});
    }
}

struct SqueezedGrid {
  static constexpr int kNx = 24, kNy = 12;
  int nx = kNx, ny = kNy;  // vertices along x and y
  flat_detail::Surface s;
  flat_detail::Embedding emb;
  std::vector<char> fixed, degenerate;
  std::vector<std::vector<int>> vf;
  // `size`: the grid is size x (24 x 12) vertices, its columns [8, 16) x size squeezed.
  explicit SqueezedGrid(double squeeze = 0.2, int size = 1) : nx(kNx * size), ny(kNy * size) {
    const int a = 8 * size, b = 16 * size;
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        s.p.push_back(flat_detail::V3(i, j, 0));
        const double x = i < a ? i : i < b ? a + squeeze * (i - a) : a + (b - a) * squeeze + (i - b);
        emb.pos.push_back(flat_detail::V2(x, j));
        fixed.push_back(i == 0 || j == 0 || i == nx - 1 || j == ny - 1);
      }
    grid_triangles(nx, ny, s.t);
    emb.dy.assign(s.t.size(), {0.0, 0.0, 0.0});
    emb.period = 1000;
    degenerate.assign(s.t.size(), 0);
    vf = flat_detail::vertex_faces(s);
  }
  // Smallest 2D / 3D area ratio of any face.
  double min_ratio() const {
    double m = 1e300;
    for (std::size_t f = 0; f < s.t.size(); ++f)
      m = std::min(m, emb.area2(s, int(f)) / flat_detail::face_area_3d(s, int(f)));
    return m;
  }
};

}  // namespace cf::test_shapes
