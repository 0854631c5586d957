#include "colonflat/denoise/homology.h"

#include <deque>

#include "colonflat/core/error.h"

namespace cf {

void HomologyBasis::build(const Mesh& mesh) {
  const std::size_t F = mesh.n_faces(), E = mesh.n_edges(), V = mesh.n_vertices();
  // Virtual faces: one per boundary loop, numbered F, F+1, ...
  std::vector<int> boundary_face(mesh.n_halfedges(), -1);  // virtual face id of a boundary halfedge
  int n_virtual = 0;
  for (auto h : mesh.halfedges()) {
    if (!mesh.is_boundary(h) || boundary_face[h.idx()] >= 0) continue;
    const int id = static_cast<int>(F) + n_virtual++;
    auto x = h;
    do {
      boundary_face[x.idx()] = id;
      x = mesh.next_halfedge_handle(x);
    } while (x != h);
  }
  const std::size_t NF = F + n_virtual;
  auto face_of = [&](Mesh::HalfedgeHandle h) -> int {
    return mesh.is_boundary(h) ? boundary_face[h.idx()] : mesh.face_handle(h).idx();
  };
  // Halfedges of a (real or virtual) face.
  std::vector<Mesh::HalfedgeHandle> virtual_start(n_virtual);
  for (auto h : mesh.halfedges())
    if (mesh.is_boundary(h)) virtual_start[boundary_face[h.idx()] - F] = h;
  auto face_halfedge = [&](int f) -> Mesh::HalfedgeHandle {
    return f < static_cast<int>(F) ? mesh.halfedge_handle(Mesh::FaceHandle(f)) : virtual_start[f - F];
  };

  // Dual spanning forest by breadth-first search; parent_edge[f] = primal edge crossed to reach f.
  std::vector<int> parent_edge(NF, -2), order;
  order.reserve(NF);
  std::vector<std::uint8_t> in_dual_tree(E, 0);
  for (std::size_t root = 0; root < NF; ++root) {
    if (parent_edge[root] != -2) continue;
    parent_edge[root] = -1;
    std::deque<int> q{static_cast<int>(root)};
    while (!q.empty()) {
      const int f = q.front();
      q.pop_front();
      order.push_back(f);
      const auto h0 = face_halfedge(f);
      auto h = h0;
      do {
        const int g = face_of(mesh.opposite_halfedge_handle(h));
        if (parent_edge[g] == -2) {
          parent_edge[g] = mesh.edge_handle(h).idx();
          in_dual_tree[mesh.edge_handle(h).idx()] = 1;
          q.push_back(g);
        }
        h = mesh.next_halfedge_handle(h);
      } while (h != h0);
    }
  }
  // Cut graph G = edges not dual to the tree; spanning forest T of G by BFS; X = G \ T.
  cut_edge_.assign(E, 0);
  for (std::size_t e = 0; e < E; ++e) cut_edge_[e] = !in_dual_tree[e];
  std::vector<std::uint8_t> seen(V, 0), in_tree(E, 0);
  for (std::size_t r = 0; r < V; ++r) {
    if (seen[r] || mesh.is_isolated(Mesh::VertexHandle(static_cast<int>(r)))) continue;
    seen[r] = 1;
    std::deque<int> q{static_cast<int>(r)};
    while (!q.empty()) {
      const auto v = Mesh::VertexHandle(q.front());
      q.pop_front();
      for (auto h : mesh.voh_range(v)) {
        const int e = mesh.edge_handle(h).idx();
        if (!cut_edge_[e]) continue;
        const int w = mesh.to_vertex_handle(h).idx();
        if (seen[w]) continue;
        seen[w] = 1;
        in_tree[e] = 1;
        q.push_back(w);
      }
    }
  }
  std::vector<int> x_edges;
  for (std::size_t e = 0; e < E; ++e)
    if (cut_edge_[e] && !in_tree[e]) x_edges.push_back(static_cast<int>(e));
  rank_ = static_cast<int>(x_edges.size());
  words_ = std::max(1, (rank_ + 63) / 64);
  ann_.assign(E * words_, 0);
  for (int i = 0; i < rank_; ++i) ann_[std::size_t(x_edges[i]) * words_ + i / 64] |= (1ull << (i % 64));
  // Leaf peeling of the dual forest: children before parents.
  for (auto it = order.rbegin(); it != order.rend(); ++it) {
    const int f = *it;
    const int pe = parent_edge[f];
    if (pe < 0) continue;
    std::uint64_t* dst = &ann_[std::size_t(pe) * words_];
    const auto h0 = face_halfedge(f);
    auto h = h0;
    do {
      const int e = mesh.edge_handle(h).idx();
      if (e != pe) xor_into(dst, &ann_[std::size_t(e) * words_], words_);
      h = mesh.next_halfedge_handle(h);
    } while (h != h0);
  }
  // Pruned cut graph: remove degree-1 vertices recursively.
  pruned_edge_ = cut_edge_;
  std::vector<int> degree(V, 0);
  for (std::size_t e = 0; e < E; ++e) {
    if (!cut_edge_[e]) continue;
    const auto h = mesh.halfedge_handle(Mesh::EdgeHandle(static_cast<int>(e)), 0);
    ++degree[mesh.from_vertex_handle(h).idx()];
    ++degree[mesh.to_vertex_handle(h).idx()];
  }
  std::vector<int> stack;
  for (std::size_t v = 0; v < V; ++v)
    if (degree[v] == 1) stack.push_back(static_cast<int>(v));
  while (!stack.empty()) {
    const auto v = Mesh::VertexHandle(stack.back());
    stack.pop_back();
    if (degree[v.idx()] != 1) continue;
    for (auto h : mesh.voh_range(v)) {
      const int e = mesh.edge_handle(h).idx();
      if (!pruned_edge_[e]) continue;
      pruned_edge_[e] = 0;
      --degree[v.idx()];
      const int w = mesh.to_vertex_handle(h).idx();
      if (--degree[w] == 1) stack.push_back(w);
      break;
    }
  }
  pruned_vertices_.clear();
  for (std::size_t v = 0; v < V; ++v)
    if (degree[v] >= 2) pruned_vertices_.push_back(static_cast<int>(v));
}

void HomologyBasis::set_edge_class(Mesh::EdgeHandle e, const std::uint64_t* cls) {
  const std::size_t need = (std::size_t(e.idx()) + 1) * words_;
  if (ann_.size() < need) ann_.resize(std::max(need, ann_.size() * 3 / 2), 0);
  std::copy(cls, cls + words_, &ann_[std::size_t(e.idx()) * words_]);
}

std::vector<int> HomologyBasis::pruned_cut_graph_vertices() const { return pruned_vertices_; }

bool Z2Span::reduce(std::uint64_t* v) const {
  for (std::size_t r = 0; r < rows_.size(); ++r) {
    const int p = pivots_[r];
    if (v[p / 64] >> (p % 64) & 1ull) xor_into(v, rows_[r].data(), words_);
  }
  return is_zero(v, words_);
}

bool Z2Span::contains(const std::uint64_t* v) const {
  std::vector<std::uint64_t> tmp(v, v + words_);
  return reduce(tmp.data());
}

bool Z2Span::insert(const std::uint64_t* v) {
  std::vector<std::uint64_t> r(v, v + words_);
  if (reduce(r.data())) return false;
  int p = 0;
  while (!(r[p / 64] >> (p % 64) & 1ull)) ++p;
  for (auto& row : rows_)
    if (row[p / 64] >> (p % 64) & 1ull) xor_into(row.data(), r.data(), words_);
  rows_.push_back(std::move(r));
  pivots_.push_back(p);
  return true;
}

}  // namespace cf
