#include "brute_force.h"

#include <algorithm>
#include <deque>
#include <limits>
#include <queue>
#include <set>
#include <unordered_set>

namespace cf::testing {

bool loop_separates(const Mesh& mesh, const std::vector<Mesh::VertexHandle>& loop) {
  std::unordered_set<int> cut;
  Mesh::HalfedgeHandle h0;
  for (std::size_t i = 0; i < loop.size(); ++i) {
    auto h = mesh.find_halfedge(loop[i], loop[(i + 1) % loop.size()]);
    cut.insert(mesh.edge_handle(h).idx());
    if (i == 0) h0 = h;
  }
  const auto fa = mesh.face_handle(h0), fb = mesh.face_handle(mesh.opposite_halfedge_handle(h0));
  if (fa == fb) return false;
  std::vector<int> mark(mesh.n_faces(), 0);
  std::deque<Mesh::FaceHandle> qa{fa}, qb{fb};
  mark[fa.idx()] = 1;
  mark[fb.idx()] = 2;
  while (!qa.empty() && !qb.empty()) {
    auto& q = qa.size() <= qb.size() ? qa : qb;
    const int me = (&q == &qa) ? 1 : 2;
    const std::size_t layer = q.size();
    for (std::size_t i = 0; i < layer; ++i) {
      const auto f = q.front();
      q.pop_front();
      for (auto h : mesh.fh_range(f)) {
        if (cut.count(mesh.edge_handle(h).idx())) continue;
        const auto g = mesh.face_handle(mesh.opposite_halfedge_handle(h));
        if (!g.is_valid()) continue;
        if (mark[g.idx()] == 0) {
          mark[g.idx()] = me;
          q.push_back(g);
        } else if (mark[g.idx()] != me) {
          return false;  // both sides meet: the loop does not separate
        }
      }
    }
  }
  return true;  // one side was exhausted without meeting the other
}

double brute_force_shortest_nonseparating(const Mesh& mesh, double upper_bound, std::vector<Mesh::VertexHandle>* out) {
  struct Cand {
    double value;
    int s, u, v;
  };
  std::vector<Cand> cands;
  const int n = static_cast<int>(mesh.n_vertices());
  std::vector<double> dist(n);
  std::vector<int> parent(n), branch(n);
  std::vector<int> all_parents;  // parent arrays of every source, n x n (meshes of a few thousand vertices)
  all_parents.assign(static_cast<std::size_t>(n) * n, -1);
  auto dijkstra = [&](int s) {
    std::fill(dist.begin(), dist.end(), std::numeric_limits<double>::infinity());
    std::fill(parent.begin(), parent.end(), -1);
    std::fill(branch.begin(), branch.end(), -1);
    using Item = std::pair<double, int>;
    std::priority_queue<Item, std::vector<Item>, std::greater<Item>> q;
    dist[s] = 0;
    q.push({0, s});
    while (!q.empty()) {
      auto [d, x] = q.top();
      q.pop();
      if (d > dist[x]) continue;
      for (auto w : mesh.vv_range(Mesh::VertexHandle(x))) {
        if (mesh.is_boundary(w)) continue;
        const double nd = d + (mesh.point(w) - mesh.point(Mesh::VertexHandle(x))).norm();
        if (nd < dist[w.idx()]) {
          dist[w.idx()] = nd;
          parent[w.idx()] = x;
          branch[w.idx()] = x == s ? w.idx() : branch[x];
          q.push({nd, w.idx()});
        }
      }
    }
  };
  for (int s = 0; s < n; ++s) {
    if (mesh.is_boundary(Mesh::VertexHandle(s)) || mesh.is_isolated(Mesh::VertexHandle(s))) continue;
    dijkstra(s);
    std::copy(parent.begin(), parent.end(), all_parents.begin() + static_cast<std::size_t>(s) * n);
    for (auto e : mesh.edges()) {
      const auto h = mesh.halfedge_handle(e, 0);
      const int u = mesh.from_vertex_handle(h).idx(), v = mesh.to_vertex_handle(h).idx();
      if (!std::isfinite(dist[u]) || !std::isfinite(dist[v])) continue;
      if (parent[u] == v || parent[v] == u) continue;  // tree edge
      if (u != s && v != s && branch[u] == branch[v]) continue;  // cycle does not pass through s
      const double value = dist[u] + mesh.calc_edge_length(e) + dist[v];
      if (value <= upper_bound) cands.push_back({value, s, u, v});
    }
  }
  std::sort(cands.begin(), cands.end(), [](const Cand& a, const Cand& b) { return a.value < b.value; });
  std::set<std::vector<int>> tested;
  for (const auto& c : cands) {
    const int* parent_of = all_parents.data() + static_cast<std::size_t>(c.s) * n;
    std::vector<Mesh::VertexHandle> loop;
    std::vector<Mesh::VertexHandle> a, b;
    for (int x = c.u; x >= 0; x = parent_of[x]) a.push_back(Mesh::VertexHandle(x));
    for (int x = c.v; x >= 0; x = parent_of[x]) b.push_back(Mesh::VertexHandle(x));
    // a: u..s, b: v..s; loop = s..u then v..(child of s)
    for (auto it = a.rbegin(); it != a.rend(); ++it) loop.push_back(*it);
    for (std::size_t i = 0; i + 1 < b.size(); ++i) loop.push_back(b[i]);
    std::vector<int> key;
    for (auto v : loop) key.push_back(v.idx());
    std::sort(key.begin(), key.end());
    if (!tested.insert(key).second) continue;
    if (!loop_separates(mesh, loop)) {
      if (out) *out = loop;
      return c.value;
    }
  }
  return std::numeric_limits<double>::infinity();
}

}  // namespace cf::testing
