#pragma once
// A flat 24 x 12 grid (z = 0, 1 mm spacing) whose map squeezes the middle 8 columns to `squeeze` of
// their width, its ends and rims fixed: a tiny band for the area correction and balancing tests.
#include <algorithm>

#include "../src/flatten_internal.h"

namespace cf::test_shapes {

struct SqueezedGrid {
  static constexpr int kNx = 24, kNy = 12;
  flat_detail::Surface s;
  flat_detail::Embedding emb;
  std::vector<char> fixed, degenerate;
  std::vector<std::vector<int>> vf;
  explicit SqueezedGrid(double squeeze = 0.2) {
    for (int j = 0; j < kNy; ++j)
      for (int i = 0; i < kNx; ++i) {
        s.p.push_back(flat_detail::V3(i, j, 0));
        const double x = i < 8 ? i : i < 16 ? 8 + squeeze * (i - 8) : 8 + 8 * squeeze + (i - 16);
        emb.pos.push_back(flat_detail::V2(x, j));
        fixed.push_back(i == 0 || j == 0 || i == kNx - 1 || j == kNy - 1);
      }
    for (int j = 0; j + 1 < kNy; ++j)
      for (int i = 0; i + 1 < kNx; ++i) {
        const int a = j * kNx + i;
        s.t.push_back({a, a + 1, a + kNx + 1});
        s.t.push_back({a, a + kNx + 1, a + kNx});
      }
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
