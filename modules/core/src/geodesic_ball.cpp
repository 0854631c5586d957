#include "colonflat/core/geodesic_ball.h"

#include "colonflat/core/quad_heap.h"
#include "colonflat/core/vertex_stamps.h"

#include <algorithm>
#include <cstdint>
#include <utility>

namespace cf {

namespace {

// Per-thread distance labels by vertex id, kept between calls: a label counts only when its stamp
// is the current call's, so a call touches only the vertices it reaches (a hash map of them cost
// 1.4 s of CPU in one denoise of a 2.1 M-face surface: the far-first balls and the bounds lowered
// near each surgery, about a hundred calls of up to the whole surface). The heap keeps its storage
// between calls (issue 26, session 23: the far-first balls of the real CT's last cuts settle up
// to a million vertices each, on the search's critical path).
struct BallScratch {
  VertexStamps stamps;   // labelled this call
  VertexStamps targets;  // a target of this call (vertices_within_until)
  std::vector<double> dist;
  QuadHeap heap;  // (distance, vertex), stale entries included; pops as std::pair orders

  void start(std::size_t vertices) {
    stamps.start(vertices);
    targets.start(vertices);
    dist.resize(stamps.size(), 0.0);
    heap.clear();
  }
  bool labelled(int v) const { return stamps.marked(v); }
  void label(int v, double d) {
    stamps.mark(v);
    dist[std::size_t(v)] = d;
  }
  // Flags v as a target of this call; false when it already was.
  bool add_target(int v) {
    if (targets.marked(v)) return false;
    targets.mark(v);
    return true;
  }
  bool is_target(int v) const { return targets.marked(v); }
};

// The multi-source Dijkstra of both functions; with `targets`, it stops right after settling the
// last of them. The heap pops (distance, vertex) pairs in std::pair order, as the
// std::priority_queue this used before did, and a vertex's label is the minimum over its settled
// neighbours whatever order they are visited in: the same vertices, order and distances
// (GeodesicBall tests); stopping early only cuts that sequence short.
std::vector<int> settle_ball(const Mesh& mesh, const std::vector<Mesh::VertexHandle>& seeds, double radius,
                             const std::vector<int>* targets, std::vector<double>* distances) {
  thread_local BallScratch scratch;
  scratch.start(mesh.n_vertices());
  std::size_t remaining = 0;
  if (targets)
    for (int t : *targets) remaining += scratch.add_target(t) ? 1 : 0;
  QuadHeap& heap = scratch.heap;
  for (auto s : seeds) {
    scratch.label(s.idx(), 0);
    heap.push(0, s.idx());
  }
  std::vector<int> out;
  while (!heap.empty()) {
    const auto [d, v] = heap.top();
    heap.pop();
    if (d > scratch.dist[std::size_t(v)]) continue;
    out.push_back(v);
    if (distances) distances->push_back(d);
    if (targets && scratch.is_target(v) && --remaining == 0) break;
    const Vec3& p = mesh.point(Mesh::VertexHandle(v));
    // The outgoing halfedges read directly (the vertex-vertex circulator's bookkeeping cost more
    // than the relaxation itself); a boundary vertex's halfedge is its outgoing boundary one, so
    // the walk covers its whole fan.
    const Mesh::HalfedgeHandle first = mesh.halfedge_handle(Mesh::VertexHandle(v));
    if (!first.is_valid()) continue;
    Mesh::HalfedgeHandle h = first;
    do {
      const Mesh::VertexHandle w = mesh.to_vertex_handle(h);
      const double nd = d + (mesh.point(w) - p).norm();
      if (nd <= radius && (!scratch.labelled(w.idx()) || nd < scratch.dist[std::size_t(w.idx())])) {
        scratch.label(w.idx(), nd);
        heap.push(nd, w.idx());
      }
      h = mesh.next_halfedge_handle(mesh.opposite_halfedge_handle(h));
    } while (h != first);
  }
  return out;
}

}  // namespace

std::vector<int> vertices_within(const Mesh& mesh, const std::vector<Mesh::VertexHandle>& seeds, double radius,
                                 std::vector<double>* distances) {
  return settle_ball(mesh, seeds, radius, nullptr, distances);
}

std::vector<int> vertices_within_until(const Mesh& mesh, const std::vector<Mesh::VertexHandle>& seeds, double radius,
                                       const std::vector<int>& targets, std::vector<double>* distances) {
  if (targets.empty()) return {};
  return settle_ball(mesh, seeds, radius, &targets, distances);
}

}  // namespace cf
