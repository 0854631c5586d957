#include "colonflat/core/geodesic_ball.h"

#include <functional>
#include <queue>
#include <unordered_map>
#include <utility>

namespace cf {

std::vector<int> vertices_within(const Mesh& mesh, const std::vector<Mesh::VertexHandle>& seeds, double radius,
                                 std::vector<double>* distances) {
  std::unordered_map<int, double> dist;
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  for (auto s : seeds) {
    dist[s.idx()] = 0;
    queue.push({0, s.idx()});
  }
  std::vector<int> out;
  while (!queue.empty()) {
    const auto [d, v] = queue.top();
    queue.pop();
    if (d > dist[v]) continue;
    out.push_back(v);
    if (distances) distances->push_back(d);
    const Vec3& p = mesh.point(Mesh::VertexHandle(v));
    for (auto w : mesh.vv_range(Mesh::VertexHandle(v))) {
      const double nd = d + (mesh.point(w) - p).norm();
      if (nd > radius) continue;
      auto it = dist.find(w.idx());
      if (it == dist.end() || nd < it->second) {
        dist[w.idx()] = nd;
        queue.push({nd, w.idx()});
      }
    }
  }
  return out;
}

}  // namespace cf
