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

}  // namespace

TopologyReport analyze_topology(const TriangleList& m) {
  TopologyReport r;
  const std::size_t P = m.points.size();
  const std::size_t F = m.triangles.size();
  r.faces = F;

  // Referenced vertices and bounding box.
  std::vector<std::uint8_t> referenced(P, 0);
  for (const auto& t : m.triangles)
    for (int v : t) referenced[v] = 1;
  r.bbox_min = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
                std::numeric_limits<double>::infinity()};
  r.bbox_max = {-r.bbox_min[0], -r.bbox_min[1], -r.bbox_min[2]};
  for (std::size_t v = 0; v < P; ++v) {
    if (!referenced[v]) {
      ++r.unreferenced_vertices;
      continue;
    }
    ++r.vertices;
    for (int a = 0; a < 3; ++a) {
      r.bbox_min[a] = std::min(r.bbox_min[a], m.points[v][a]);
      r.bbox_max[a] = std::max(r.bbox_max[a], m.points[v][a]);
    }
  }
  if (r.vertices == 0) {
    r.bbox_min = r.bbox_max = {0, 0, 0};
    return r;
  }

  // Group directed edges by undirected key.
  std::vector<HalfRecord> recs(3 * F);
  for (std::size_t f = 0; f < F; ++f) {
    const auto& t = m.triangles[f];
    for (std::uint32_t k = 0; k < 3; ++k) {
      std::uint64_t a = static_cast<std::uint32_t>(t[k]), b = static_cast<std::uint32_t>(t[(k + 1) % 3]);
      if (a > b) std::swap(a, b);
      recs[3 * f + k] = {(a << 32) | b, static_cast<std::uint32_t>(f), k};
    }
  }
  std::sort(recs.begin(), recs.end(), [](const HalfRecord& x, const HalfRecord& y) {
    return x.key < y.key || (x.key == y.key && x.face < y.face);
  });

  UnionFind face_uf(F);
  UnionFind corner_uf(3 * F);  // fans around vertices
  ParityUnionFind orient(F);
  UnionFind boundary_uf(P);
  std::vector<std::uint8_t> on_boundary(P, 0), on_nonmanifold_edge(P, 0);
  std::vector<std::uint8_t> face_bad(F, 0);  // touches a non-manifold edge
  std::vector<std::uint32_t> edge_face;      // one face per unique edge (for per-component counts)
  std::vector<std::uint8_t> edge_is_boundary;
  edge_face.reserve(3 * F / 2 + 16);
  edge_is_boundary.reserve(3 * F / 2 + 16);
  double length_sum = 0;
  bool orientable = true;
  std::vector<std::uint32_t> contradiction_faces;

  for (std::size_t i = 0; i < recs.size();) {
    std::size_t j = i + 1;
    while (j < recs.size() && recs[j].key == recs[i].key) ++j;
    const std::size_t n = j - i;
    const int a = static_cast<int>(recs[i].key >> 32), b = static_cast<int>(recs[i].key & 0xffffffffu);
    const auto& pa = m.points[a];
    const auto& pb = m.points[b];
    length_sum += std::sqrt((pa[0] - pb[0]) * (pa[0] - pb[0]) + (pa[1] - pb[1]) * (pa[1] - pb[1]) +
                            (pa[2] - pb[2]) * (pa[2] - pb[2]));
    edge_face.push_back(recs[i].face);
    edge_is_boundary.push_back(n == 1);
    for (std::size_t q = i + 1; q < j; ++q) face_uf.unite(recs[i].face, recs[q].face);
    if (n == 1) {
      ++r.boundary_edges;
      push_example(r.example_boundary_edges, {a, b});
      on_boundary[a] = on_boundary[b] = 1;
      boundary_uf.unite(a, b);
    } else if (n == 2) {
      const HalfRecord& x = recs[i];
      const HalfRecord& y = recs[i + 1];
      const auto& tx = m.triangles[x.face];
      const auto& ty = m.triangles[y.face];
      // Same direction in both triangles -> the two faces are oppositely oriented.
      const bool same_dir = tx[x.k] == ty[y.k];
      if (same_dir) {
        ++r.inconsistent_edges;
        push_example(r.example_inconsistent_edges, {a, b});
      }
      if (!orient.unite(x.face, y.face, same_dir ? 1 : 0)) {
        orientable = false;
        contradiction_faces.push_back(x.face);
      }
      corner_uf.unite(3 * x.face + corner_of(tx, a), 3 * y.face + corner_of(ty, a));
      corner_uf.unite(3 * x.face + corner_of(tx, b), 3 * y.face + corner_of(ty, b));
    } else {
      ++r.nonmanifold_edges;
      push_example(r.example_nonmanifold_edges, {a, b});
      on_nonmanifold_edge[a] = on_nonmanifold_edge[b] = 1;
      for (std::size_t q = i; q < j; ++q) face_bad[recs[q].face] = 1;
    }
    i = j;
  }
  r.edges = edge_face.size();
  r.mean_edge_length = r.edges ? length_sum / static_cast<double>(r.edges) : 0.0;
  recs.clear();
  recs.shrink_to_fit();

  // Fans per vertex; faces sharing a vertex are in one component.
  std::vector<std::uint32_t> first_face(P, std::numeric_limits<std::uint32_t>::max());
  std::vector<std::uint32_t> first_fan(P, std::numeric_limits<std::uint32_t>::max());
  std::vector<std::uint8_t> vertex_bad(P, 0);
  for (std::size_t f = 0; f < F; ++f) {
    for (int k = 0; k < 3; ++k) {
      const int v = m.triangles[f][k];
      if (first_face[v] == std::numeric_limits<std::uint32_t>::max()) {
        first_face[v] = static_cast<std::uint32_t>(f);
      } else {
        face_uf.unite(first_face[v], static_cast<std::uint32_t>(f));
      }
      const std::uint32_t fan = corner_uf.find(static_cast<std::uint32_t>(3 * f + k));
      if (first_fan[v] == std::numeric_limits<std::uint32_t>::max()) {
        first_fan[v] = fan;
      } else if (first_fan[v] != fan) {
        vertex_bad[v] = 1;
      }
    }
  }
  for (std::size_t v = 0; v < P; ++v) {
    if (referenced[v] && (vertex_bad[v] || on_nonmanifold_edge[v])) {
      ++r.nonmanifold_vertices;
      push_example(r.example_nonmanifold_vertices, static_cast<int>(v));
    }
  }

  // Components, numbered by root, then sorted largest first.
  std::vector<int> root_id(F, -1);
  std::vector<ComponentTopology> comps;
  r.face_component.assign(F, -1);
  for (std::size_t f = 0; f < F; ++f) {
    const std::uint32_t root = face_uf.find(static_cast<std::uint32_t>(f));
    if (root_id[root] < 0) {
      root_id[root] = static_cast<int>(comps.size());
      comps.emplace_back();
      comps.back().manifold = true;
      comps.back().orientable = true;
    }
    const int c = root_id[root];
    r.face_component[f] = c;
    ++comps[c].faces;
    if (face_bad[f]) comps[c].manifold = false;
  }
  for (std::size_t v = 0; v < P; ++v) {
    if (!referenced[v]) continue;
    auto& c = comps[r.face_component[first_face[v]]];
    ++c.vertices;
    if (vertex_bad[v] || on_nonmanifold_edge[v]) c.manifold = false;
  }
  for (std::size_t e = 0; e < edge_face.size(); ++e) {
    auto& c = comps[r.face_component[edge_face[e]]];
    ++c.edges;
    if (edge_is_boundary[e]) ++c.boundary_edges;
  }
  // Boundary loops: connected sets of boundary vertices.
  std::vector<std::uint8_t> loop_counted(P, 0);
  for (std::size_t v = 0; v < P; ++v) {
    if (!on_boundary[v]) continue;
    const std::uint32_t root = boundary_uf.find(static_cast<std::uint32_t>(v));
    if (loop_counted[root]) continue;
    loop_counted[root] = 1;
    ++comps[r.face_component[first_face[v]]].boundary_loops;
  }
  // Orientability per component: a parity contradiction marks its component.
  for (std::uint32_t f : contradiction_faces) comps[r.face_component[f]].orientable = false;

  // Per-component Euler characteristic and genus.
  bool all_genus = true;
  int genus_sum = 0;
  for (auto& c : comps) {
    c.euler = static_cast<long long>(c.vertices) - static_cast<long long>(c.edges) +
              static_cast<long long>(c.faces);
    c.closed = c.boundary_edges == 0;
    if (c.manifold && c.orientable) {
      const long long twice = 2 - c.euler - static_cast<long long>(c.boundary_loops);
      c.genus = static_cast<int>(twice / 2);
      genus_sum += *c.genus;
    } else {
      all_genus = false;
    }
  }
  // Sort components largest first and renumber face_component.
  std::vector<int> order(comps.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  std::stable_sort(order.begin(), order.end(),
                   [&](int x, int y) { return comps[x].faces > comps[y].faces; });
  std::vector<int> new_id(comps.size());
  for (std::size_t i = 0; i < order.size(); ++i) {
    new_id[order[i]] = static_cast<int>(i);
    r.components.push_back(comps[order[i]]);
  }
  for (auto& c : r.face_component) c = new_id[c];

  r.euler = static_cast<long long>(r.vertices) - static_cast<long long>(r.edges) +
            static_cast<long long>(r.faces);
  for (const auto& c : r.components) r.boundary_loops += c.boundary_loops;
  r.closed = r.boundary_edges == 0;
  r.manifold = r.nonmanifold_edges == 0 && r.nonmanifold_vertices == 0;
  r.orientable = orientable;
  r.consistently_oriented = r.inconsistent_edges == 0 && r.manifold;
  if (all_genus) r.genus = genus_sum;
  return r;
}

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
