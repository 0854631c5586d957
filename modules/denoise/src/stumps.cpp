#include "colonflat/denoise/stumps.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <limits>
#include <unordered_map>
#include <unordered_set>

#include "colonflat/core/error.h"
#include "colonflat/core/geodesic_ball.h"
#include "colonflat/denoise/cap_triangulation.h"
#include "colonflat/denoise/face_grid.h"

namespace cf {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kBaseTries = 32;  // regions tried, walking back from the first too-long front

// Surface points in order of geodesic (graph) distance from the ring, up to `cutoff`.
struct Growth {
  std::vector<Mesh::VertexHandle> order;  // settled vertices, nearest first
  std::vector<double> dist;               // their distances
  std::unordered_map<int, int> rank;      // vertex id -> index in order
};

Growth grow(const Mesh& mesh, const std::vector<Mesh::VertexHandle>& ring, double cutoff) {
  Growth g;
  for (int v : vertices_within(mesh, ring, cutoff, &g.dist)) {
    g.rank[v] = static_cast<int>(g.order.size());
    g.order.push_back(Mesh::VertexHandle(v));
  }
  return g;
}

// The region's boundary as one simple cycle of vertices (the region on its left), or nothing when
// the region is not a disk bounded by one simple cycle or reaches the mesh boundary.
std::vector<Mesh::VertexHandle> disk_boundary(const Mesh& mesh, const std::vector<Mesh::FaceHandle>& region,
                                              const std::unordered_set<int>& in_region) {
  std::unordered_map<int, Mesh::HalfedgeHandle> out;  // boundary halfedge leaving each vertex
  std::unordered_set<int> verts, edges;
  for (auto f : region)
    for (auto h : mesh.fh_range(f)) {
      verts.insert(mesh.to_vertex_handle(h).idx());
      edges.insert(mesh.edge_handle(h).idx());
      const auto g = mesh.opposite_face_handle(h);
      if (!g.is_valid()) return {};  // reaches the mesh boundary
      if (in_region.count(g.idx())) continue;
      if (!out.emplace(mesh.from_vertex_handle(h).idx(), h).second) return {};  // pinched
    }
  if (out.empty()) return {};
  if (static_cast<long long>(verts.size()) - static_cast<long long>(edges.size()) +
          static_cast<long long>(region.size()) != 1)
    return {};  // not a disk
  std::vector<Mesh::VertexHandle> cycle;
  auto h = out.begin()->second;
  do {
    cycle.push_back(mesh.from_vertex_handle(h));
    auto it = out.find(mesh.to_vertex_handle(h).idx());
    if (it == out.end() || cycle.size() > out.size()) return {};
    h = it->second;
  } while (h != out.begin()->second);
  if (cycle.size() != out.size()) return {};  // several boundary cycles
  return cycle;
}

double cycle_length(const Mesh& mesh, const std::vector<Mesh::VertexHandle>& c) {
  double len = 0;
  for (std::size_t i = 0; i < c.size(); ++i) len += (mesh.point(c[(i + 1) % c.size()]) - mesh.point(c[i])).norm();
  return len;
}

// Faces join the region when their last vertex is settled; the front (the region's boundary
// length) after each settled vertex. Returns how many vertices were processed (stops at the
// mesh boundary).
int front_lengths(const Mesh& mesh, const Growth& g, std::unordered_map<int, int>* face_rank, std::vector<double>* front) {
  front->assign(g.order.size(), 0.0);
  double len_now = 0;
  int reach = 0;
  for (int q = 0; q < static_cast<int>(g.order.size()); ++q, ++reach) {
    const auto v = g.order[q];
    if (mesh.is_boundary(v)) break;
    for (auto f : mesh.vf_range(v)) {
      if (face_rank->count(f.idx())) continue;
      bool all = true;
      for (auto w : mesh.fv_range(f)) {
        auto it = g.rank.find(w.idx());
        all = all && it != g.rank.end() && it->second <= q;
      }
      if (!all) continue;
      (*face_rank)[f.idx()] = q;
      for (auto h : mesh.fh_range(f)) {
        const auto o2 = mesh.opposite_face_handle(h);
        const double len = mesh.calc_edge_length(mesh.edge_handle(h));
        len_now += o2.is_valid() && face_rank->count(o2.idx()) ? -len : len;
      }
    }
    (*front)[q] = len_now;
  }
  return reach;
}

// The base: the first rank from which the front stays longer than `limit` over a stretch of
// `window` mm (a front is jagged: single vertices make it jump); -1 when there is none.
int first_too_long(const Growth& g, const std::vector<double>& front, int reach, double limit, double window) {
  for (int q = 0, end = 0; q < reach; ++q) {
    if (g.dist[q] <= 0) continue;
    end = std::max(end, q);
    while (end + 1 < reach && g.dist[end + 1] <= g.dist[q] + window) ++end;
    if (g.dist[end] < g.dist[q] + window && end + 1 >= reach) break;  // runs out before the window
    bool above = true;
    for (int u = q; u <= end && above; ++u) above = front[u] > limit;
    if (above) return q;
  }
  return -1;
}

// Removes the region of faces joined up to rank p if it is a disk with one simple boundary that
// can be capped without intersections; true on success (the stump is appended to `out`).
bool remove_region(Mesh& mesh, FaceGrid& grid, const std::unordered_map<int, int>& face_rank, int p,
                   StumpRecord record, std::vector<StumpRecord>& out) {
  std::vector<Mesh::FaceHandle> region;
  std::unordered_set<int> in_region;
  for (const auto& [fi, r] : face_rank)
    if (r <= p) {
      region.push_back(Mesh::FaceHandle(fi));
      in_region.insert(fi);
    }
  const std::vector<Mesh::VertexHandle> base = disk_boundary(mesh, region, in_region);
  if (base.size() < 3) return false;
  // A diagonal that stays an edge after the region is gone would make the cap non-manifold.
  auto blocked = [&](Mesh::VertexHandle a, Mesh::VertexHandle b) {
    const auto h = mesh.find_halfedge(a, b);
    if (!h.is_valid()) return false;
    const auto f1 = mesh.face_handle(h), f2 = mesh.opposite_face_handle(h);
    return !(f1.is_valid() && in_region.count(f1.idx()) && f2.is_valid() && in_region.count(f2.idx()));
  };
  for (auto f : region) grid.erase(mesh, f);
  std::vector<std::array<int, 3>> cap = triangulate_ring(mesh, base, blocked);
  if (cap.empty() || grid.count_triangles(mesh, cap) != 0) cap = triangulate_ring(mesh, base, blocked, &grid);
  if (cap.empty()) {
    for (auto f : region) grid.insert(mesh, f);
    return false;
  }
  for (auto f : region) mesh.delete_face(f, true);
  add_cap(mesh, cap, &grid, "stump removal");
  record.base_length_mm = cycle_length(mesh, base);
  record.faces_removed = region.size();
  record.cap_faces = cap.size();
  out.push_back(record);
  return true;
}

// One ring: find the finger's base and remove the finger (walking back from the base to the
// largest region that is a disk with one simple boundary and can be capped).
void remove_stump_at(Mesh& mesh, FaceGrid& grid, std::size_t ring_id, const std::vector<Mesh::VertexHandle>& ring,
                     const StumpOptions& o, double mean_edge, std::vector<StumpRecord>& out) {
  const double ring_len = cycle_length(mesh, ring);
  const Growth g = grow(mesh, ring, o.max_length + ring_len);
  std::unordered_map<int, int> face_rank;  // face -> rank at which it joined
  std::vector<double> front;
  const int reach = front_lengths(mesh, g, &face_rank, &front);
  const double window = std::max(0.5 * ring_len, 2 * mean_edge);
  const int too_long = first_too_long(g, front, reach, o.growth * ring_len, window);
  if (too_long < 0 || g.dist[too_long] > o.max_length) return;  // no base within reach
  const double min_length = ring_len / kPi;  // a finger at least as long as it is wide
  for (int p = too_long - 1, tries = 0; p >= 0 && tries < kBaseTries; --p) {
    if (g.dist[p] > o.max_length) continue;
    if (g.dist[p] < min_length) break;
    if (p + 1 < static_cast<int>(g.order.size()) && g.dist[p + 1] == g.dist[p]) continue;  // mid-tie
    ++tries;
    if (remove_region(mesh, grid, face_rank, p, StumpRecord{ring_id, g.dist[p], ring_len, 0, 0, 0}, out)) return;
  }
}

}  // namespace

std::vector<StumpRecord> remove_stumps(Mesh& mesh, const std::vector<std::vector<Mesh::VertexHandle>>& rings,
                                       const StumpOptions& o) {
  if (!(o.max_length > 0) || !(o.growth > 1))
    throw UsageError("stump removal needs max_length > 0 and growth > 1");
  mesh.request_vertex_status();
  mesh.request_edge_status();
  mesh.request_halfedge_status();
  mesh.request_face_status();
  double mean_edge = 0;
  for (auto e : mesh.edges()) mean_edge += mesh.calc_edge_length(e);
  mean_edge /= std::max<std::size_t>(1, mesh.n_edges());
  FaceGrid grid(mesh, 2 * mean_edge);
  std::vector<StumpRecord> out;
  for (std::size_t ri = 0; ri < rings.size(); ++ri) {
    const auto& ring = rings[ri];
    if (ring.size() < 3 || std::any_of(ring.begin(), ring.end(), [&](auto v) { return mesh.status(v).deleted(); }))
      continue;
    remove_stump_at(mesh, grid, ri, ring, o, mean_edge, out);
  }
  mesh.garbage_collection();
  mesh.release_face_status();  // as requested above (OpenMesh counts requests)
  mesh.release_halfedge_status();
  mesh.release_edge_status();
  mesh.release_vertex_status();
  return out;
}

}  // namespace cf
