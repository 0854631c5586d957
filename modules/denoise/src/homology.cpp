#include "colonflat/denoise/homology.h"

#include <algorithm>
#include <cstdio>

#include "colonflat/core/error.h"
#include "colonflat/core/huge_pages.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/core/union_find.h"
#include "denoise_debug.h"

namespace cf {

namespace detail {

// The dual graph of the mesh closed by one virtual face per boundary loop (ids F, F+1, ...).
struct ClosedDual {
  const Mesh& mesh;
  std::size_t real_faces;
  std::vector<int> boundary_face;  // per halfedge: its virtual face, or -1 (empty on a closed mesh)
  std::vector<Mesh::HalfedgeHandle> virtual_start;  // a halfedge of each virtual face

  explicit ClosedDual(const Mesh& m) : mesh(m), real_faces(m.n_faces()) {
    for (auto h : mesh.halfedges()) {
      if (!mesh.is_boundary(h)) continue;
      if (boundary_face.empty()) boundary_face.assign(mesh.n_halfedges(), -1);  // not on a closed mesh
      if (boundary_face[h.idx()] >= 0) continue;
      const int id = static_cast<int>(real_faces + virtual_start.size());
      virtual_start.push_back(h);
      auto x = h;
      do {
        boundary_face[x.idx()] = id;
        x = mesh.next_halfedge_handle(x);
      } while (x != h);
    }
  }
  std::size_t faces() const { return real_faces + virtual_start.size(); }
  int face_of(Mesh::HalfedgeHandle h) const {
    return mesh.is_boundary(h) ? boundary_face[h.idx()] : mesh.face_handle(h).idx();
  }
  Mesh::HalfedgeHandle face_halfedge(int f) const {
    return f < static_cast<int>(real_faces) ? mesh.halfedge_handle(Mesh::FaceHandle(f)) : virtual_start[f - real_faces];
  }
};

}  // namespace detail

namespace {

using detail::ClosedDual;

// Dual spanning forest by breadth-first search (Algorithm 1): parent_edge[f] = primal edge
// crossed to reach f (-1 at roots); `order` = faces in visiting order; in_tree flags the edges.
void dual_spanning_forest(const ClosedDual& dual, std::vector<int>& parent_edge, std::vector<int>& order,
                          std::vector<std::uint8_t>& in_tree) {
  const Mesh& mesh = dual.mesh;
  assign_huge(parent_edge, dual.faces(), -2);
  order.clear();
  reserve_huge(order, dual.faces());
  in_tree.assign(mesh.n_edges(), 0);
  for (std::size_t root = 0; root < dual.faces(); ++root) {
    if (parent_edge[root] != -2) continue;
    parent_edge[root] = -1;
    std::size_t head = order.size();
    order.push_back(static_cast<int>(root));
    while (head < order.size()) {  // `order` doubles as the queue
      const int f = order[head++];
      const auto h0 = dual.face_halfedge(f);
      auto h = h0;
      do {
        const int g = dual.face_of(mesh.opposite_halfedge_handle(h));
        if (parent_edge[g] == -2) {
          parent_edge[g] = mesh.edge_handle(h).idx();
          in_tree[mesh.edge_handle(h).idx()] = 1;
          order.push_back(g);
        }
        h = mesh.next_halfedge_handle(h);
      } while (h != h0);
    }
  }
}

// Edges of the cut graph outside a spanning forest of it (the 2g edges X): Kruskal's forest in
// edge id order, which reads the edge records in memory order (a breadth-first forest
// circulated every vertex's halfedges: a dependent, scattered read per edge end).
std::vector<int> cut_graph_leftovers(const Mesh& mesh, const std::vector<std::uint8_t>& cut_edge) {
  UnionFind forest(mesh.n_vertices());
  std::vector<int> x_edges;
  for (std::size_t e = 0; e < mesh.n_edges(); ++e) {
    if (!cut_edge[e]) continue;
    const auto h = mesh.halfedge_handle(Mesh::EdgeHandle(static_cast<int>(e)), 0);
    const auto a = static_cast<std::uint32_t>(mesh.from_vertex_handle(h).idx());
    const auto b = static_cast<std::uint32_t>(mesh.to_vertex_handle(h).idx());
    if (!forest.unite(a, b)) x_edges.push_back(static_cast<int>(e));
  }
  return x_edges;
}

}  // namespace

void HomologyBasis::build(const Mesh& mesh, const RunBoth& run_both) {
  Stopwatch sw;
  const detail::ClosedDual dual(mesh);
  std::vector<int> parent_edge, order;
  std::vector<std::uint8_t> in_dual_tree;
  dual_spanning_forest(dual, parent_edge, order, in_dual_tree);
  // Cut graph G = edges not dual to the tree; X = G minus a spanning forest of G.
  cut_edge_.assign(mesh.n_edges(), 0);
  for (std::size_t e = 0; e < mesh.n_edges(); ++e) cut_edge_[e] = !in_dual_tree[e];
  const double t_forest = sw.seconds();
  double t_annotate = 0, t_prune = 0;
  auto annotate = [&] {
    Stopwatch s;
    annotate_edges(mesh, dual, parent_edge, order);
    t_annotate = s.seconds();
  };
  auto prune = [&] {
    Stopwatch s;
    prune_cut_graph(mesh);
    t_prune = s.seconds();
  };
  // Both read the mesh, the forest and cut_edge_ only and write disjoint members.
  if (run_both) {
    run_both(annotate, prune);
    ++builds_on_two_threads_;
  } else {
    annotate();
    prune();
  }
  if (detail::denoise_debug())
    std::fprintf(stderr, "denoise debug: homology build: dual forest %.3f s, annotation %.3f s, pruning %.3f s%s\n",
                 t_forest, t_annotate, t_prune, run_both ? " (beside it)" : "");
}

// Annotations: unit vectors on the leftover edges X (Kruskal's forest of the cut graph), zero on
// the rest of G, and on the dual forest's edges by leaf peeling, children before parents: the
// parent edge of a face gets the XOR of its other edges (final by then), so that the face sums
// to zero.
void HomologyBasis::annotate_edges(const Mesh& mesh, const detail::ClosedDual& dual, const std::vector<int>& parent_edge,
                                   const std::vector<int>& order) {
  const std::vector<int> x_edges = cut_graph_leftovers(mesh, cut_edge_);
  rank_ = static_cast<int>(x_edges.size());
  words_ = std::max(1, (rank_ + 63) / 64);
  assign_huge(row_of_, mesh.n_edges(), 0u);
  rows_.assign(words_, 0);  // row 0: the zero class
  std::vector<std::uint64_t> cls(words_, 0);
  for (int i = 0; i < rank_; ++i) {
    std::fill(cls.begin(), cls.end(), 0);
    cls[i / 64] = 1ull << (i % 64);
    row_of_[x_edges[i]] = new_row(cls.data());
  }
  for (auto it = order.rbegin(); it != order.rend(); ++it) {
    const int pe = parent_edge[*it];
    if (pe < 0) continue;
    bool any = false;  // most faces have only zero classes around them: no vector work
    const auto h0 = dual.face_halfedge(*it);
    auto h = h0;
    do {
      const int e = mesh.edge_handle(h).idx();
      const std::uint32_t row = row_of_[e];
      if (e != pe && row != 0) {
        if (!any) std::fill(cls.begin(), cls.end(), 0);
        any = true;
        xor_into(cls.data(), &rows_[std::size_t(row) * words_], words_);
      }
      h = mesh.next_halfedge_handle(h);
    } while (h != h0);
    if (any && !is_zero(cls.data(), words_)) row_of_[pe] = new_row(cls.data());
  }
}

// Pruned cut graph: degree-1 vertices removed recursively (the 2-core: the same whatever the
// order). The cut graph's adjacency is gathered once into compressed rows, so that peeling a
// leaf reads its few cut edges instead of circulating its mesh halfedges.
void HomologyBasis::prune_cut_graph(const Mesh& mesh) {
  const std::size_t V = mesh.n_vertices(), E = mesh.n_edges();
  pruned_edge_ = cut_edge_;
  auto ends = [&](std::size_t e) {
    const auto h = mesh.halfedge_handle(Mesh::EdgeHandle(static_cast<int>(e)), 0);
    return std::pair<int, int>(mesh.from_vertex_handle(h).idx(), mesh.to_vertex_handle(h).idx());
  };
  std::vector<std::uint32_t> start(V + 1, 0);  // counts, then row starts
  for (std::size_t e = 0; e < E; ++e)
    if (cut_edge_[e]) {
      const auto [a, b] = ends(e);
      ++start[a + 1];
      ++start[b + 1];
    }
  std::vector<int> degree(V);
  for (std::size_t v = 0; v < V; ++v) degree[v] = static_cast<int>(start[v + 1]), start[v + 1] += start[v];
  std::vector<std::pair<int, int>> adjacent;  // per vertex: (cut edge, other end)
  resize_huge(adjacent, start[V]);
  for (std::size_t e = 0; e < E; ++e)  // filled through start[v] (moved one row along), shifted back after
    if (cut_edge_[e]) {
      const auto [a, b] = ends(e);
      adjacent[start[a]++] = {static_cast<int>(e), b};
      adjacent[start[b]++] = {static_cast<int>(e), a};
    }
  for (std::size_t v = V; v > 0; --v) start[v] = start[v - 1];
  start[0] = 0;
  peel_leaves(start, adjacent, degree);
  pruned_vertices_.clear();
  for (std::size_t v = 0; v < V; ++v)
    if (degree[v] >= 2) pruned_vertices_.push_back(static_cast<int>(v));
}

void HomologyBasis::peel_leaves(const std::vector<std::uint32_t>& start, const std::vector<std::pair<int, int>>& adjacent,
                                std::vector<int>& degree) {
  std::vector<int> stack;
  for (std::size_t v = 0; v < degree.size(); ++v)
    if (degree[v] == 1) stack.push_back(static_cast<int>(v));
  while (!stack.empty()) {
    const int v = stack.back();
    stack.pop_back();
    if (degree[v] != 1) continue;
    for (std::uint32_t i = start[v]; i < start[v + 1]; ++i) {
      const auto [e, w] = adjacent[i];
      if (!pruned_edge_[e]) continue;
      pruned_edge_[e] = 0;
      --degree[v];
      if (--degree[w] == 1) stack.push_back(w);
      break;
    }
  }
}

std::uint32_t HomologyBasis::new_row(const std::uint64_t* cls) {
  const std::size_t row = rows_.size() / words_;
  if (row > 0xffffffffu) throw Error("homology: more class rows than 32-bit ids");
  rows_.insert(rows_.end(), cls, cls + words_);
  return static_cast<std::uint32_t>(row);
}

void HomologyBasis::set_edge_class(Mesh::EdgeHandle e, const std::uint64_t* cls) {
  const std::size_t id = static_cast<std::size_t>(e.idx());
  if (row_of_.size() <= id) row_of_.resize(std::max(id + 1, row_of_.size() + row_of_.size() / 8), 0);
  if (is_zero(cls, words_)) row_of_[id] = 0;  // an own row (if any) stays unused
  else if (row_of_[id] != 0) std::copy(cls, cls + words_, &rows_[std::size_t(row_of_[id]) * words_]);
  else row_of_[id] = new_row(cls);
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
