#include "colonflat/core/topology.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>

#include "colonflat/core/huge_pages.h"
#include "colonflat/core/union_find.h"
#include "colonflat/core/vertex_corners.h"

namespace cf {
namespace {

// Union-find with parity, to 2-colour faces by orientation (orientability test).
class ParityUnionFind {
 public:
  explicit ParityUnionFind(std::size_t n) {
    resize_huge(parent_, n);
    assign_huge(parity_, n, std::uint8_t(0));
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

// One half-edge incident to the vertex being scanned: between it and `other`, in triangle
// `face`, starting at that triangle's corner `k`; `corner` is the local index (in the vertex's
// corner list) of the triangle's first corner at the vertex.
struct Incident {
  std::uint32_t other, face, corner;
  std::uint8_t k;
};

inline bool incident_less(const Incident& x, const Incident& y) {
  if (x.other != y.other) return x.other < y.other;
  return x.face != y.face ? x.face < y.face : x.k < y.k;
}

// Insertion sort for the few half-edges around a vertex; std::sort around a large fan.
void sort_incident(Incident* inc, std::size_t n) {
  if (n > 32) {
    std::sort(inc, inc + n, incident_less);
    return;
  }
  for (std::size_t i = 1; i < n; ++i) {
    const Incident x = inc[i];
    std::size_t j = i;
    for (; j > 0 && incident_less(x, inc[j - 1]); --j) inc[j] = inc[j - 1];
    inc[j] = x;
  }
}

// The steps of analyze_topology over one triangle list, sharing their state (geometry-central
// style: one short method per step, run in order by run()). Edges are found around each vertex
// from its corners (one counting sort, no edge table) and classified at their lower end, in
// the (min, max) order of a sorted edge table.
// Point: anything p with p[0], p[1], p[2] (std::array<double, 3>, OpenMesh's Vec3), read in place.
template <class Point>
class TopologyAnalysis {
 public:
  TopologyAnalysis(const Point* points, std::size_t n_points, const std::vector<std::array<int, 3>>& triangles)
      : points_(points), triangles_(triangles), P_(n_points), F_(triangles.size()), face_uf_(F_), orient_(F_) {}

  TopologyReport run() {
    r_.faces = F_;
    corners_ = vertex_corners(triangles_, P_);
    if (!count_vertices_and_bounds()) return std::move(r_);
    scan_vertices();
    count_nonmanifold_vertices();
    build_components();
    count_component_elements();
    count_boundary_loops();
    compute_genera();
    sort_components();
    finish_totals();
    return std::move(r_);
  }

 private:
  bool referenced(std::size_t v) const { return corners_.start[v + 1] != corners_.start[v]; }
  std::uint32_t first_face(std::size_t v) const { return corners_.corner[corners_.start[v]] / 3; }

  // Referenced vertices and bounding box; false when no vertex is referenced.
  bool count_vertices_and_bounds() {
    const double inf = std::numeric_limits<double>::infinity();
    r_.bbox_min = {inf, inf, inf};
    r_.bbox_max = {-inf, -inf, -inf};
    for (std::size_t v = 0; v < P_; ++v) {
      if (!referenced(v)) {
        ++r_.unreferenced_vertices;
        continue;
      }
      ++r_.vertices;
      for (int a = 0; a < 3; ++a) {
        r_.bbox_min[a] = std::min(r_.bbox_min[a], points_[v][a]);
        r_.bbox_max[a] = std::max(r_.bbox_max[a], points_[v][a]);
      }
    }
    if (r_.vertices == 0) r_.bbox_min = r_.bbox_max = {0, 0, 0};
    return r_.vertices != 0;
  }

  // Per vertex v: its incident half-edges grouped by their other end. Edges whose lower end is
  // v are classified; v's corners are joined into fans along its manifold edges (more than one
  // fan: non-manifold vertex); v's triangles join one component.
  void scan_vertices() {
    on_boundary_.assign(P_, 0);
    on_nonmanifold_edge_.assign(P_, 0);
    vertex_bad_.assign(P_, 0);
    face_bad_.assign(F_, 0);
    edges_from_.assign(P_, 0);
    boundary_from_.assign(P_, 0);
    for (std::size_t v = 0; v < P_; ++v) {
      const std::uint32_t degree = corners_.degree(v);
      if (degree == 0) continue;
      gather_incident(static_cast<std::uint32_t>(v));
      fans_.reset(degree);
      for (std::size_t i = 0; i < n_incident_;) {
        std::size_t j = i + 1;
        while (j < n_incident_ && incident_[j].other == incident_[i].other) ++j;
        if (j - i == 2) fans_.unite(incident_[i].corner, incident_[i + 1].corner);
        if (incident_[i].other >= v) classify_edge(static_cast<std::uint32_t>(v), i, j);
        i = j;
      }
      vertex_bad_[v] = !one_fan(degree);
      const std::uint32_t* c = corners_.begin(v);
      for (std::uint32_t i = 1; i < degree; ++i) face_uf_.unite(c[0] / 3, c[i] / 3);
    }
    r_.mean_edge_length = r_.edges ? length_sum_ / static_cast<double>(r_.edges) : 0.0;
  }

  bool one_fan(std::uint32_t degree) {
    const std::uint32_t root = fans_.find(0);
    for (std::uint32_t i = 1; i < degree; ++i)
      if (fans_.find(i) != root) return false;
    return true;
  }

  // The half-edges of v's corners (out of each corner and into it; a half-edge from v to v
  // once), sorted by (other end, face, corner).
  void gather_incident(std::uint32_t v) {
    if (incident_.size() < 2 * corners_.degree(v)) incident_.resize(2 * corners_.degree(v));
    n_incident_ = 0;
    const std::uint32_t* c = corners_.begin(v);
    std::uint32_t first = 0;
    for (std::uint32_t i = 0; i < corners_.degree(v); ++i) {
      const std::uint32_t f = c[i] / 3, k = c[i] % 3;
      if (i == 0 || c[i - 1] / 3 != f) first = i;  // a triangle's corners at v are adjacent
      const auto& t = triangles_[f];
      incident_[n_incident_++] = {static_cast<std::uint32_t>(t[(k + 1) % 3]), f, first, static_cast<std::uint8_t>(k)};
      const auto prev = static_cast<std::uint32_t>(t[(k + 2) % 3]);
      if (prev != v) incident_[n_incident_++] = {prev, f, first, static_cast<std::uint8_t>((k + 2) % 3)};
    }
    sort_incident(incident_.data(), n_incident_);
  }

  // The edge (a, b), b = incident_[i].other >= a, with half-edges incident_[i .. j).
  void classify_edge(std::uint32_t a, std::size_t i, std::size_t j) {
    const std::uint32_t b = incident_[i].other;
    const auto& pa = points_[a];
    const auto& pb = points_[b];
    length_sum_ += std::sqrt((pa[0] - pb[0]) * (pa[0] - pb[0]) + (pa[1] - pb[1]) * (pa[1] - pb[1]) +
                             (pa[2] - pb[2]) * (pa[2] - pb[2]));
    ++r_.edges;
    ++edges_from_[a];
    if (j - i == 1) {
      ++boundary_from_[a];
      boundary_edge(a, b);
    } else if (j - i == 2) {
      manifold_edge(a, b, incident_[i], incident_[i + 1]);
    } else {
      nonmanifold_edge(a, b, i, j);
    }
  }

  void boundary_edge(std::uint32_t a, std::uint32_t b) {
    ++r_.boundary_edges;
    push_example(r_.example_boundary_edges, {static_cast<int>(a), static_cast<int>(b)});
    on_boundary_[a] = on_boundary_[b] = 1;
    if (boundary_uf_.size() == 0) boundary_uf_.reset(P_);
    boundary_uf_.unite(a, b);
  }

  // Two triangles: orientation consistency (the fans are joined around each end vertex).
  void manifold_edge(std::uint32_t a, std::uint32_t b, const Incident& x, const Incident& y) {
    const bool same_dir = triangles_[x.face][x.k] == triangles_[y.face][y.k];  // oppositely oriented faces
    if (same_dir) {
      ++r_.inconsistent_edges;
      push_example(r_.example_inconsistent_edges, {static_cast<int>(a), static_cast<int>(b)});
    }
    if (!orient_.unite(x.face, y.face, same_dir ? 1 : 0)) {
      orientable_ = false;
      contradiction_faces_.push_back(x.face);
    }
  }

  void nonmanifold_edge(std::uint32_t a, std::uint32_t b, std::size_t i, std::size_t j) {
    ++r_.nonmanifold_edges;
    push_example(r_.example_nonmanifold_edges, {static_cast<int>(a), static_cast<int>(b)});
    on_nonmanifold_edge_[a] = on_nonmanifold_edge_[b] = 1;
    for (std::size_t q = i; q < j; ++q) face_bad_[incident_[q].face] = 1;
  }

  // A vertex with more than one fan, or on a non-manifold edge.
  void count_nonmanifold_vertices() {
    for (std::size_t v = 0; v < P_; ++v)
      if (referenced(v) && (vertex_bad_[v] || on_nonmanifold_edge_[v])) {
        ++r_.nonmanifold_vertices;
        push_example(r_.example_nonmanifold_vertices, static_cast<int>(v));
      }
  }

  // Components numbered by root of the face union-find.
  void build_components() {
    std::vector<int> root_id;
    assign_huge(root_id, F_, -1);
    assign_huge(r_.face_component, F_, -1);
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

  // Vertices, edges (counted at their lower end) and boundary edges per component.
  void count_component_elements() {
    for (std::size_t v = 0; v < P_; ++v) {
      if (!referenced(v)) continue;
      auto& c = comps_[r_.face_component[first_face(v)]];
      ++c.vertices;
      c.edges += edges_from_[v];
      c.boundary_edges += boundary_from_[v];
      if (vertex_bad_[v] || on_nonmanifold_edge_[v]) c.manifold = false;
    }
    for (std::uint32_t f : contradiction_faces_) comps_[r_.face_component[f]].orientable = false;
  }

  // Boundary loops: connected sets of boundary vertices.
  void count_boundary_loops() {
    if (r_.boundary_edges == 0) return;
    std::vector<std::uint8_t> loop_counted(P_, 0);
    for (std::size_t v = 0; v < P_; ++v) {
      if (!on_boundary_[v]) continue;
      const std::uint32_t root = boundary_uf_.find(static_cast<std::uint32_t>(v));
      if (loop_counted[root]) continue;
      loop_counted[root] = 1;
      ++comps_[r_.face_component[first_face(v)]].boundary_loops;
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

  const Point* points_;
  const std::vector<std::array<int, 3>>& triangles_;
  const std::size_t P_, F_;  // #points, #triangles
  TopologyReport r_;
  VertexCorners corners_;
  UnionFind face_uf_;  // triangles sharing a vertex
  ParityUnionFind orient_;
  UnionFind boundary_uf_;  // boundary vertices joined along boundary edges (sized at the first one)
  UnionFind fans_;  // the corners of the vertex being scanned, joined along its manifold edges
  std::vector<Incident> incident_;  // the first n_incident_ hold the scanned vertex's half-edges
  std::size_t n_incident_ = 0;
  std::vector<std::uint8_t> on_boundary_, on_nonmanifold_edge_, face_bad_, vertex_bad_;
  std::vector<std::uint32_t> edges_from_, boundary_from_;  // per vertex: edges, boundary edges with it as lower end
  std::vector<std::uint32_t> contradiction_faces_;
  std::vector<ComponentTopology> comps_;
  double length_sum_ = 0;
  bool orientable_ = true, all_genus_ = true;
  int genus_sum_ = 0;
};

}  // namespace

TopologyReport analyze_topology(const TriangleList& m) {
  return TopologyAnalysis<std::array<double, 3>>(m.points.data(), m.points.size(), m.triangles).run();
}

std::vector<std::array<int, 3>> mesh_triangles(const Mesh& mesh) {
  std::vector<std::array<int, 3>> triangles;
  reserve_huge(triangles, mesh.n_faces());
  for (auto f : mesh.faces()) {
    std::array<int, 3> tri{};
    int k = 0;
    for (auto v : mesh.fv_range(f)) {
      if (k < 3) tri[k] = v.idx();
      ++k;
    }
    triangles.push_back(tri);
  }
  return triangles;
}

TriangleList to_triangle_list(const Mesh& mesh) {
  TriangleList t;
  t.points.resize(mesh.n_vertices());
  for (auto v : mesh.vertices()) {
    const auto& p = mesh.point(v);
    t.points[v.idx()] = {p[0], p[1], p[2]};
  }
  t.triangles = mesh_triangles(mesh);
  return t;
}

bool has_deleted_elements(const Mesh& mesh) {
  for (std::size_t f = 0; f < mesh.n_faces(); ++f)
    if (mesh.status(Mesh::FaceHandle(int(f))).deleted()) return true;
  for (std::size_t v = 0; v < mesh.n_vertices(); ++v)
    if (mesh.status(Mesh::VertexHandle(int(v))).deleted()) return true;
  return false;
}

bool topology_fits(const TopologyReport& t, const TriangleList& mesh) {
  if (t.faces != mesh.triangles.size() || t.face_component.size() != mesh.triangles.size() ||
      t.vertices + t.unreferenced_vertices != mesh.points.size())
    return false;
  if (t.unreferenced_vertices != 0 || mesh.points.empty()) return true;
  std::array<double, 3> lo = mesh.points[0], hi = mesh.points[0];
  for (const auto& p : mesh.points)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  return lo == t.bbox_min && hi == t.bbox_max;
}

TopologyReport known_or_analysed(const TopologyReport* known, const TriangleList& mesh) {
  return known && topology_fits(*known, mesh) ? *known : analyze_topology(mesh);
}

// The mesh's points are read in place (no copy of 24 bytes per vertex).
TopologyReport analyze_topology(const Mesh& mesh) {
  return TopologyAnalysis<Vec3>(mesh.points(), mesh.n_vertices(), mesh_triangles(mesh)).run();
}

}  // namespace cf
