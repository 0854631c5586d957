// Triangles in a hash of cells by bounding box (triangle_hash.h).
#include "triangle_hash.h"

#include <cmath>

#include "colonflat/denoise/face_grid.h"

namespace cf::detail {

std::array<Vec3, 3> TriangleHash::points(const std::array<int, 3>& t) const {
  return {mesh_.point(Mesh::VertexHandle(t[0])), mesh_.point(Mesh::VertexHandle(t[1])), mesh_.point(Mesh::VertexHandle(t[2]))};
}

TriangleHash::Box TriangleHash::box_of(const std::array<Vec3, 3>& p) {
  Box b{p[0], p[0]};
  for (int i = 1; i < 3; ++i) b.lo.minimize(p[i]), b.hi.maximize(p[i]);
  return b;
}

// Calls f(cell key) for every cell the box meets.
template <class F>
void TriangleHash::for_cells(const Box& b, F&& f) const {
  auto key = [this](double x) { return static_cast<long long>(std::floor(x / cell_)); };
  for (long long z = key(b.lo[2]); z <= key(b.hi[2]); ++z)
    for (long long y = key(b.lo[1]); y <= key(b.hi[1]); ++y)
      for (long long x = key(b.lo[0]); x <= key(b.hi[0]); ++x) f((x * 73856093LL) ^ (y * 19349663LL) ^ (z * 83492791LL));
}

int TriangleHash::insert(const std::array<int, 3>& t) {
  const int id = static_cast<int>(tris_.size());
  tris_.push_back(t);
  boxes_.push_back(box_of(points(t)));
  stamp_.push_back(-1);
  for_cells(boxes_.back(), [&](long long k) { grid_[k].push_back(id); });
  return id;
}

int TriangleHash::crossing(const std::array<int, 3>& t) const {
  const std::array<Vec3, 3> p = points(t);
  const Box b = box_of(p);
  const int query = ++query_;
  int found = -1;
  for_cells(b, [&](long long k) {
    const auto it = grid_.find(k);
    if (found >= 0 || it == grid_.end()) return;
    for (int u : it->second) {
      if (stamp_[u] == query) continue;
      stamp_[u] = query;
      const Box& o = boxes_[u];
      bool apart = false;
      for (int a = 0; a < 3; ++a) apart = apart || o.lo[a] > b.hi[a] || o.hi[a] < b.lo[a];
      if (!apart && triangles_intersect_improperly(t, p, tris_[u], points(tris_[u]))) {
        found = u;
        return;
      }
    }
  });
  return found;
}

}  // namespace cf::detail
