#include "colonflat/core/voxel_path.h"

#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <utility>

namespace cf {

namespace {
// The 26 neighbour offsets with their step lengths (mm).
struct Step {
  int di, dj, dk;
  float mm;
};

std::vector<Step> neighbour_steps(const std::array<double, 3>& sp) {
  std::vector<Step> steps;
  for (int dk = -1; dk <= 1; ++dk)
    for (int dj = -1; dj <= 1; ++dj)
      for (int di = -1; di <= 1; ++di) {
        if (di == 0 && dj == 0 && dk == 0) continue;
        const double len = std::sqrt(di * di * sp[0] * sp[0] + dj * dj * sp[1] * sp[1] + dk * dk * sp[2] * sp[2]);
        steps.push_back({di, dj, dk, float(len)});
      }
  return steps;
}
}  // namespace

std::vector<float> voxel_path_distance(const VoxelBox& box, const std::array<int, 3>& start) {
  std::vector<float> dist(box.box_size(), std::numeric_limits<float>::infinity());
  const std::vector<Step> steps = neighbour_steps(box.spacing);
  auto inside = [&](int i, int j, int k) {
    return i >= box.lo[0] && j >= box.lo[1] && k >= box.lo[2] && i < box.hi[0] && j < box.hi[1] && k < box.hi[2] &&
           box.mask[(std::size_t(k) * box.dims[1] + j) * box.dims[0] + i] != 0;
  };
  if (!inside(start[0], start[1], start[2])) return dist;
  using Item = std::pair<float, std::array<int, 3>>;
  auto later = [](const Item& a, const Item& b) { return a.first > b.first; };
  std::priority_queue<Item, std::vector<Item>, decltype(later)> heap(later);
  dist[box.box_index(start[0], start[1], start[2])] = 0;
  heap.push({0.f, start});
  while (!heap.empty()) {
    const auto [d, v] = heap.top();
    heap.pop();
    if (d > dist[box.box_index(v[0], v[1], v[2])]) continue;
    for (const Step& s : steps) {
      const int a = v[0] + s.di, b = v[1] + s.dj, c = v[2] + s.dk;
      if (!inside(a, b, c)) continue;
      float& cur = dist[box.box_index(a, b, c)];
      if (d + s.mm < cur) cur = d + s.mm, heap.push({d + s.mm, {a, b, c}});
    }
  }
  return dist;
}

}  // namespace cf
