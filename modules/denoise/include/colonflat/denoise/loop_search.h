#pragma once
// Bounded shortest-path searches for non-separating loops.
//
// FundamentalCycleSearch runs Dijkstra from a source s over the mesh (Euclidean edge lengths,
// boundary vertices excluded) and examines the fundamental cycles of the shortest-path tree:
// for a non-tree edge uv, the cycle path(s,u) + uv + path(v,s) of value d(u) + |uv| + d(v).
// By Thomassen's 3-path argument (the property "class not in the span" is closed under the
// 3-path condition), the shortest non-separating cycle through s is such a fundamental cycle,
// so minimising over a vertex set that every non-separating cycle meets gives the global
// shortest. Since d(u) + |uv| + d(v) >= 2 max(d(u), d(v)), cycles of value <= L involve only
// vertices within L/2: the search stops at half the best value found (or of the limit).
#include <cstdint>
#include <functional>
#include <limits>
#include <queue>
#include <vector>

#include "colonflat/core/mesh.h"
#include "colonflat/core/quad_heap.h"
#include "colonflat/denoise/homology.h"
#include "colonflat/denoise/vertex_adjacency.h"

namespace cf {

struct CycleCandidate {
  bool found = false;
  double value = std::numeric_limits<double>::infinity();  // d(u) + |uv| + d(v)
  Mesh::VertexHandle source, u, v;
  bool truncated = false;  // the search stopped at the limit with vertices left unexplored
  // When truncated: the length of the shortest closed walk with a class outside the span seen
  // across the search frontier (settled u, edge uw, tentative path to w). It contains a
  // non-separating cycle, so it bounds the global shortest one from above; used to choose the
  // next search radius instead of blind doubling.
  double frontier_bound = std::numeric_limits<double>::infinity();
};

class FundamentalCycleSearch {
 public:
  using Accept = std::function<bool(const std::vector<Mesh::VertexHandle>& loop)>;
  FundamentalCycleSearch(const Mesh& mesh, const HomologyBasis& homology, const Z2Span& cut_classes);

  // Best fundamental cycle of value <= limit whose class is not in `cut_classes` (and that
  // `accept` approves, when given). The search state is kept for extract().
  // With `frontier`, a truncated search without a loop also computes frontier_bound.
  CycleCandidate run(Mesh::VertexHandle s, double limit, const Accept* accept = nullptr, bool frontier = false);
  // Multi-root search: one run from a tree T of roots whose edges count as length 0 (classes and
  // cochain sums as they are). `roots` are vertex ids, `root_parent[i]` the halfedge from an
  // earlier root to roots[i] (-1 for roots[0]). Every closed walk W through a root t extends
  // (T-path to t, W, back) to a walk through roots[0] of the same class and no greater length,
  // so the result's value M (or the limit when truncated without a loop) bounds F(t) from below
  // for every root t, and F(t) >= M - 2 d(t, T) for every vertex t settled. When the extracted
  // cycle uses no edge of T (its real length equals M), it is a real closed walk through its
  // first vertex, a root: F(that root) = M exactly. Precondition: the roots are interior.
  CycleCandidate run_group(const std::vector<int>& roots, const std::vector<int>& root_parent, double limit);
  // Cochain mode: with an edge cochain x (one flag per edge id), run() looks for cycles whose
  // edges have an odd sum of x instead of a class outside the span. That family also satisfies
  // the 3-path condition (the sum is additive), so the same fundamental-cycle argument holds.
  // nullptr: span mode. The cochain must outlive the runs.
  void set_cochain(const std::vector<std::uint8_t>* cochain);
  // Vertices flagged in `avoid` (per vertex id) are never entered (the source excepted);
  // nullptr: none. Must outlive the runs.
  void set_avoid(const std::vector<std::uint8_t>* avoid) { avoid_ = avoid; }
  // The walks read each vertex's neighbours and edge lengths from `adjacency` (kept up to date
  // with the mesh by the caller; the same neighbours, order and lengths as the halfedges, so the
  // same results, faster); nullptr: from the mesh's halfedges. Must outlive the runs.
  void set_adjacency(const VertexAdjacency* adjacency) { adj_ = adjacency; }
  // The simple cycle of a candidate from the last run() (the common stem from s is dropped).
  std::vector<Mesh::VertexHandle> extract(const CycleCandidate& c);
  // Class of an edge cycle (XOR of edge classes), `words()` words.
  std::vector<std::uint64_t> cycle_class(const std::vector<Mesh::VertexHandle>& loop) const;
  // The root whose tree holds the settled vertex v (the first vertex at distance 0 above it).
  int root_of(int v) const {
    while (node_[v].dist > 0 && node_[v].parent >= 0) v = node_[v].from;
    return v;
  }
  std::size_t last_settled() const { return settled_count_; }
  // Vertices the last run() settled, nearest first, and their distances from its source (mm):
  // the ball whose geometry and classes the run's result depends on.
  const std::vector<int>& last_settled_vertices() const { return settled_order_; }
  double distance(int settled_vertex) const { return node_[settled_vertex].dist; }

 private:
  void grow();
  void start(Mesh::VertexHandle s);
  void start_roots(const std::vector<int>& roots, const std::vector<int>& root_parent);
  void reset_run();
  void drain(double limit, const Accept* accept, bool frontier, CycleCandidate& best);
  void expand(int vi, double d, double limit, const Accept* accept, CycleCandidate& best);
  template <class Visit>
  void for_each_out(int vi, Visit&& visit) const;  // visit(to, halfedge, length) per outgoing halfedge
  void relax(int w, double d, int parent, int from);
  void settle(int v);
  void try_cycle(int vi, int wi, int h, double value, double limit, const Accept* accept, CycleCandidate& best);
  double frontier_bound();
  bool wanted(std::uint64_t* cls) const;  // in the searched family (cls may be modified)
  const std::uint64_t* edge_bits(Mesh::EdgeHandle e) const {
    return cochain_ ? &kBit[(*cochain_)[e.idx()] & 1] : hom_.edge_class(e);
  }
  bool edge_zero(Mesh::EdgeHandle e) const {
    return cochain_ ? ((*cochain_)[e.idx()] & 1) == 0 : hom_.edge_class_is_zero(e);
  }
  static constexpr std::uint64_t kBit[2] = {0, 1};
  bool settled(int v) const { return node_[v].stamp == run_id_ && node_[v].settled; }
  const Mesh& mesh_;
  const HomologyBasis& hom_;
  const Z2Span& span_;
  const std::vector<std::uint8_t>* cochain_ = nullptr;
  const std::vector<std::uint8_t>* avoid_ = nullptr;
  const VertexAdjacency* adj_ = nullptr;
  int W_;
  std::uint32_t run_id_ = 0;
  // Per-vertex search state in one record (one cache line fetch per neighbour visited).
  struct alignas(32) Node {  // 32 bytes on 32: never across two cache lines
    double dist = 0;
    std::uint32_t stamp = 0;  // run_id_ of the run that reached it; the other fields hold only then
    int parent = -1;          // parent halfedge (parent -> v) idx, -1 at the source
    int from = -1;            // the parent halfedge's from-vertex (kept: the halfedge array is not read again)
    int slot = -1;            // row of acc_ holding the class of path(s, v)
    // Its list in the adjacency (with adj_): entries()[first, first + count), copied when the run
    // reaches it, so that expanding it reads the list without a dependent load of the span.
    std::uint32_t first = 0;
    std::uint16_t count = 0;  // kLongList: longer, read from the adjacency's span
    std::uint8_t settled = 0;
    std::uint8_t blocked = 0;  // boundary vertex (never on a loop); set for all vertices below blocked_known_
  };
  static_assert(sizeof(Node) == 32, "one Node per half cache line");
  static constexpr std::uint16_t kLongList = 0xffff;
  void copy_list(Node& node, int v) const;
  void prefetch_list(int vi) const;
  std::vector<Node> node_;
  std::size_t blocked_known_ = 0;
  std::vector<std::uint64_t> acc_;  // class rows of settled vertices' paths; row 0 is zero
  std::vector<std::uint64_t> tmp_;
  std::vector<std::uint32_t> mark_;
  std::uint32_t mark_id_ = 0;
  std::size_t settled_count_ = 0;
  std::vector<int> settled_order_;
  QuadHeap heap_;  // tentative (distance, vertex) entries, stale duplicates included
};

// Edge cochain whose sum over any edge cycle C is the Z2 intersection number of C with `loop`:
// the edges leaving the loop's vertices on its left side, toggled (the loop pushed off into its
// left faces crosses exactly these; a chord on that side is crossed twice). Shape: one flag per
// edge id. Precondition: `loop` is a simple edge cycle through interior vertices of an oriented
// manifold mesh. closed = false: `loop` is an open simple path (its ends toggle nothing), and the
// sum counts the crossings of a cycle with the path away from its two ends.
std::vector<std::uint8_t> crossing_cochain(const Mesh& mesh, const std::vector<Mesh::VertexHandle>& loop,
                                           bool closed = true);

// Euclidean length of a closed loop.
double loop_length(const Mesh& mesh, const std::vector<Mesh::VertexHandle>& loop);

// Handle or tunnel, relative to the solid the surface encloses (outward normals): a handle loop
// bounds a disk inside the solid, a tunnel loop a disk outside. Decided from the sign of
// sum_i n_i . (p_i - c) over the loop (n_i vertex normals, c the loop centroid): positive when
// the surface around the loop faces away from its centre (a tube seen from outside: handle).
enum class LoopType { kHandle, kTunnel };
LoopType classify_loop(const Mesh& mesh, const std::vector<Mesh::VertexHandle>& loop);
const char* loop_type_name(LoopType t);

}  // namespace cf
