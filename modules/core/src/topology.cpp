#include "colonflat/core/topology.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "colonflat/core/union_find.h"

namespace cf {
namespace {

// One directed edge of a triangle: corner k of face f goes from tri[f][k] to tri[f][(k+1)%3].
struct HalfRecord {
  std::uint64_t key;  // (min << 32) | max
  std::uint32_t face;
  std::uint32_t k;
};

inline int corner_of(const std::array<int, 3>& t, int v) {
  return t[0] == v ? 0 : (t[1] == v ? 1 : 2);
}

// Union-find with parity, to 2-colour faces by orientation (orientability test).
class ParityUnionFind {
 public:
  explicit ParityUnionFind(std::size_t n) : parent_(n), parity_(n, 0) {
    for (std::size_t i = 0; i < n; ++i) parent_[i] = static_cast<std::uint32_t>(i);
  }
  std::uint32_t find(std::uint32_t x, std::uint8_t& par) {
    par = 0;
    std::uint32_t r = x;
    while (parent_[r] != r) {
      par ^= parity_[r];
      r = parent_[r];
    }
    // Path compression with parity bookkeeping.
    std::uint8_t p = par;
    while (parent_[x] != x) {
      std::uint32_t next = parent_[x];
      std::uint8_t px = parity_[x];
      parent_[x] = r;
      parity_[x] = p;
      p ^= px;
      x = next;
    }
    return r;
  }
  // Requires parity(a) ^ parity(b) == rel; returns false on contradiction.
  bool unite(std::uint32_t a, std::uint32_t b, std::uint8_t rel) {
    std::uint8_t pa, pb;
    std::uint32_t ra = find(a, pa), rb = find(b, pb);
    if (ra == rb) return (pa ^ pb) == rel;
    parent_[rb] = ra;
    parity_[rb] = pa ^ pb ^ rel;
    return true;
  }

 private:
  std::vector<std::uint32_t> parent_;
  std::vector<std::uint8_t> parity_;
};

template <class T>
void push_example(std::vector<T>& v, const T& x) {
  if (v.size() < TopologyReport::kMaxExamples) v.push_back(x);
}

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

// The steps of analyze_topology over one triangle list, sharing their state (geometry-central
// style: one short method per step, run in order by run()).
class TopologyAnalysis {
 public:
  explicit TopologyAnalysis(const TriangleList& m)
      : m_(m), P_(m.points.size()), F_(m.triangles.size()), face_uf_(F_), corner_uf_(3 * F_), orient_(F_),
        boundary_uf_(P_) {}

  TopologyReport run() {
    r_.faces = F_;
    if (!count_vertices_and_bounds()) return std::move(r_);
    sort_directed_edges();
    classify_edges();
    find_fans();
    build_components();
    count_component_elements();
    count_boundary_loops();
    compute_genera();
    sort_components();
    finish_totals();
    return std::move(r_);
  }

 private:
  // Referenced vertices and bounding box; false when no vertex is referenced.
  bool count_vertices_and_bounds() {
    referenced_.assign(P_, 0);
    for (const auto& t : m_.triangles)
      for (int v : t) referenced_[v] = 1;
    const double inf = std::numeric_limits<double>::infinity();
    r_.bbox_min = {inf, inf, inf};
    r_.bbox_max = {-inf, -inf, -inf};
    for (std::size_t v = 0; v < P_; ++v) {
      if (!referenced_[v]) {
        ++r_.unreferenced_vertices;
        continue;
      }
      ++r_.vertices;
      for (int a = 0; a < 3; ++a) {
        r_.bbox_min[a] = std::min(r_.bbox_min[a], m_.points[v][a]);
        r_.bbox_max[a] = std::max(r_.bbox_max[a], m_.points[v][a]);
      }
    }
    if (r_.vertices == 0) r_.bbox_min = r_.bbox_max = {0, 0, 0};
    return r_.vertices != 0;
  }

  // Directed edges grouped by undirected key (then by face).
  void sort_directed_edges() {
    recs_.resize(3 * F_);
    for (std::size_t f = 0; f < F_; ++f) {
      const auto& t = m_.triangles[f];
      for (std::uint32_t k = 0; k < 3; ++k) {
        std::uint64_t a = static_cast<std::uint32_t>(t[k]), b = static_cast<std::uint32_t>(t[(k + 1) % 3]);
        if (a > b) std::swap(a, b);
        recs_[3 * f + k] = {(a << 32) | b, static_cast<std::uint32_t>(f), k};
      }
    }
    std::sort(recs_.begin(), recs_.end(), [](const HalfRecord& x, const HalfRecord& y) {
      return x.key < y.key || (x.key == y.key && x.face < y.face);
    });
  }

  // Each undirected edge: length, boundary / manifold / non-manifold, face connectivity.
  void classify_edges() {
    on_boundary_.assign(P_, 0);
    on_nonmanifold_edge_.assign(P_, 0);
    face_bad_.assign(F_, 0);
    edge_face_.reserve(3 * F_ / 2 + 16);
    edge_is_boundary_.reserve(3 * F_ / 2 + 16);
    double length_sum = 0;
    for (std::size_t i = 0; i < recs_.size();) {
      std::size_t j = i + 1;
      while (j < recs_.size() && recs_[j].key == recs_[i].key) ++j;
      const int a = static_cast<int>(recs_[i].key >> 32), b = static_cast<int>(recs_[i].key & 0xffffffffu);
      const auto& pa = m_.points[a];
      const auto& pb = m_.points[b];
      length_sum += std::sqrt((pa[0] - pb[0]) * (pa[0] - pb[0]) + (pa[1] - pb[1]) * (pa[1] - pb[1]) +
                              (pa[2] - pb[2]) * (pa[2] - pb[2]));
      edge_face_.push_back(recs_[i].face);
      edge_is_boundary_.push_back(j - i == 1);
      for (std::size_t q = i + 1; q < j; ++q) face_uf_.unite(recs_[i].face, recs_[q].face);
      if (j - i == 1) boundary_edge(a, b);
      else if (j - i == 2) manifold_edge(a, b, recs_[i], recs_[i + 1]);
      else nonmanifold_edge(a, b, i, j);
      i = j;
    }
    r_.edges = edge_face_.size();
    r_.mean_edge_length = r_.edges ? length_sum / static_cast<double>(r_.edges) : 0.0;
    recs_.clear();
    recs_.shrink_to_fit();
  }

  void boundary_edge(int a, int b) {
    ++r_.boundary_edges;
    push_example(r_.example_boundary_edges, {a, b});
    on_boundary_[a] = on_boundary_[b] = 1;
    boundary_uf_.unite(a, b);
  }

  // Two faces: orientation consistency and the fans through both end vertices.
  void manifold_edge(int a, int b, const HalfRecord& x, const HalfRecord& y) {
    const auto& tx = m_.triangles[x.face];
    const auto& ty = m_.triangles[y.face];
    const bool same_dir = tx[x.k] == ty[y.k];  // same direction: oppositely oriented faces
    if (same_dir) {
      ++r_.inconsistent_edges;
      push_example(r_.example_inconsistent_edges, {a, b});
    }
    if (!orient_.unite(x.face, y.face, same_dir ? 1 : 0)) {
      orientable_ = false;
      contradiction_faces_.push_back(x.face);
    }
    corner_uf_.unite(3 * x.face + corner_of(tx, a), 3 * y.face + corner_of(ty, a));
    corner_uf_.unite(3 * x.face + corner_of(tx, b), 3 * y.face + corner_of(ty, b));
  }

  void nonmanifold_edge(int a, int b, std::size_t i, std::size_t j) {
    ++r_.nonmanifold_edges;
    push_example(r_.example_nonmanifold_edges, {a, b});
    on_nonmanifold_edge_[a] = on_nonmanifold_edge_[b] = 1;
    for (std::size_t q = i; q < j; ++q) face_bad_[recs_[q].face] = 1;
  }

  // Fans per vertex (more than one: non-manifold vertex); faces sharing a vertex join.
  void find_fans() {
    first_face_.assign(P_, kNone);
    std::vector<std::uint32_t> first_fan(P_, kNone);
    vertex_bad_.assign(P_, 0);
    for (std::size_t f = 0; f < F_; ++f) {
      for (int k = 0; k < 3; ++k) {
        const int v = m_.triangles[f][k];
        if (first_face_[v] == kNone) first_face_[v] = static_cast<std::uint32_t>(f);
        else face_uf_.unite(first_face_[v], static_cast<std::uint32_t>(f));
        const std::uint32_t fan = corner_uf_.find(static_cast<std::uint32_t>(3 * f + k));
        if (first_fan[v] == kNone) first_fan[v] = fan;
        else if (first_fan[v] != fan) vertex_bad_[v] = 1;
      }
    }
    for (std::size_t v = 0; v < P_; ++v)
      if (referenced_[v] && (vertex_bad_[v] || on_nonmanifold_edge_[v])) {
        ++r_.nonmanifold_vertices;
        push_example(r_.example_nonmanifold_vertices, static_cast<int>(v));
      }
  }

  // Components numbered by root of the face union-find.
  void build_components() {
    std::vector<int> root_id(F_, -1);
    r_.face_component.assign(F_, -1);
    for (std::size_t f = 0; f < F_; ++f) {
      const std::uint32_t root = face_uf_.find(static_cast<std::uint32_t>(f));
      if (root_id[root] < 0) {
        root_id[root] = static_cast<int>(comps_.size());
        comps_.emplace_back();
        comps_.back().manifold = true;
        comps_.back().orientable = true;
      }
      const int c = root_id[root];
      r_.face_component[f] = c;
      ++comps_[c].faces;
      if (face_bad_[f]) comps_[c].manifold = false;
    }
  }

  void count_component_elements() {
    for (std::size_t v = 0; v < P_; ++v) {
      if (!referenced_[v]) continue;
      auto& c = comps_[r_.face_component[first_face_[v]]];
      ++c.vertices;
      if (vertex_bad_[v] || on_nonmanifold_edge_[v]) c.manifold = false;
    }
    for (std::size_t e = 0; e < edge_face_.size(); ++e) {
      auto& c = comps_[r_.face_component[edge_face_[e]]];
      ++c.edges;
      if (edge_is_boundary_[e]) ++c.boundary_edges;
    }
    for (std::uint32_t f : contradiction_faces_) comps_[r_.face_component[f]].orientable = false;
  }

  // Boundary loops: connected sets of boundary vertices.
  void count_boundary_loops() {
    std::vector<std::uint8_t> loop_counted(P_, 0);
    for (std::size_t v = 0; v < P_; ++v) {
      if (!on_boundary_[v]) continue;
      const std::uint32_t root = boundary_uf_.find(static_cast<std::uint32_t>(v));
      if (loop_counted[root]) continue;
      loop_counted[root] = 1;
      ++comps_[r_.face_component[first_face_[v]]].boundary_loops;
    }
  }

  // Per component: chi = V - E + F and g = (2 - chi - b) / 2 where defined.
  void compute_genera() {
    for (auto& c : comps_) {
      c.euler = static_cast<long long>(c.vertices) - static_cast<long long>(c.edges) +
                static_cast<long long>(c.faces);
      c.closed = c.boundary_edges == 0;
      if (c.manifold && c.orientable) {
        c.genus = static_cast<int>((2 - c.euler - static_cast<long long>(c.boundary_loops)) / 2);
        genus_sum_ += *c.genus;
      } else {
        all_genus_ = false;
      }
    }
  }

  // Largest component first; face_component renumbered.
  void sort_components() {
    std::vector<int> order(comps_.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
    std::stable_sort(order.begin(), order.end(), [&](int x, int y) { return comps_[x].faces > comps_[y].faces; });
    std::vector<int> new_id(comps_.size());
    for (std::size_t i = 0; i < order.size(); ++i) {
      new_id[order[i]] = static_cast<int>(i);
      r_.components.push_back(comps_[order[i]]);
    }
    for (auto& c : r_.face_component) c = new_id[c];
  }

  void finish_totals() {
    r_.euler = static_cast<long long>(r_.vertices) - static_cast<long long>(r_.edges) +
               static_cast<long long>(r_.faces);
    for (const auto& c : r_.components) r_.boundary_loops += c.boundary_loops;
    r_.closed = r_.boundary_edges == 0;
    r_.manifold = r_.nonmanifold_edges == 0 && r_.nonmanifold_vertices == 0;
    r_.orientable = orientable_;
    r_.consistently_oriented = r_.inconsistent_edges == 0 && r_.manifold;
    if (all_genus_) r_.genus = genus_sum_;
  }

  const TriangleList& m_;
  const std::size_t P_, F_;  // #points, #triangles
  TopologyReport r_;
  std::vector<HalfRecord> recs_;
  UnionFind face_uf_, corner_uf_;  // faces by shared vertex/edge; corners by fan around a vertex
  ParityUnionFind orient_;
  UnionFind boundary_uf_;
  std::vector<std::uint8_t> referenced_, on_boundary_, on_nonmanifold_edge_, face_bad_, vertex_bad_;
  std::vector<std::uint32_t> edge_face_;  // one face per unique edge (per-component counts)
  std::vector<std::uint8_t> edge_is_boundary_;
  std::vector<std::uint32_t> first_face_, contradiction_faces_;
  std::vector<ComponentTopology> comps_;
  bool orientable_ = true, all_genus_ = true;
  int genus_sum_ = 0;
};

}  // namespace

TopologyReport analyze_topology(const TriangleList& m) { return TopologyAnalysis(m).run(); }

TriangleList to_triangle_list(const Mesh& mesh) {
  TriangleList t;
  t.points.resize(mesh.n_vertices());
  for (auto v : mesh.vertices()) {
    const auto& p = mesh.point(v);
    t.points[v.idx()] = {p[0], p[1], p[2]};
  }
  t.triangles.reserve(mesh.n_faces());
  for (auto f : mesh.faces()) {
    std::array<int, 3> tri{};
    int k = 0;
    for (auto v : mesh.fv_range(f)) {
      if (k < 3) tri[k] = v.idx();
      ++k;
    }
    t.triangles.push_back(tri);
  }
  return t;
}

TopologyReport analyze_topology(const Mesh& mesh) { return analyze_topology(to_triangle_list(mesh)); }

}  // namespace cf
