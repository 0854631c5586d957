// Vertex adjacency of a triangle list (vertex_graph.h).
#include "colonflat/core/vertex_graph.h"

#include <algorithm>
#include <utility>

namespace cf {

VertexGraph vertex_graph(const TriangleList& surface) {
  const std::size_t n = surface.points.size();
  std::vector<std::pair<int, int>> directed;  // both directions of every triangle edge
  directed.reserve(6 * surface.triangles.size());
  for (const auto& t : surface.triangles)
    for (int k = 0; k < 3; ++k) {
      directed.emplace_back(t[k], t[(k + 1) % 3]);
      directed.emplace_back(t[(k + 1) % 3], t[k]);
    }
  std::sort(directed.begin(), directed.end());
  VertexGraph g;
  g.on_boundary.assign(n, 0);
  for (std::size_t k = 0; k < directed.size(); ++k) {  // an edge in one triangle appears once
    const bool alone = (k == 0 || directed[k - 1] != directed[k]) &&
                       (k + 1 == directed.size() || directed[k + 1] != directed[k]);
    if (alone) g.on_boundary[std::size_t(directed[k].first)] = g.on_boundary[std::size_t(directed[k].second)] = 1;
  }
  directed.erase(std::unique(directed.begin(), directed.end()), directed.end());
  g.start.assign(n + 1, 0);
  for (const auto& e : directed) ++g.start[std::size_t(e.first) + 1];
  for (std::size_t i = 0; i < n; ++i) g.start[i + 1] += g.start[i];
  g.neighbours.resize(directed.size());
  for (std::size_t k = 0; k < directed.size(); ++k) g.neighbours[k] = directed[k].second;
  return g;
}

}  // namespace cf
