#pragma once
// A compact copy of the mesh's vertex adjacency for the searches' walks (issue 26, session 37):
// per vertex, its outgoing halfedges in OpenMesh's voh_range() order, each with its to-vertex and
// the edge length (p_to - p_from).norm() the walks use, in one contiguous block. A walk over the
// halfedge arrays costs three dependent random loads per neighbour (the halfedge, its to-vertex's
// point, the search's record); here the block is one sequential read. Same neighbours, same
// order, same lengths to the bit: searches on it give the same results as on the halfedges.
// The mesh may change by surgery: refresh() rewrites the lists of the vertices it touched
// (touched_by_surgery()), after the cut and again after an undo.
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "colonflat/core/default_init_allocator.h"
#include "colonflat/core/mesh.h"
#include "colonflat/denoise/run_both.h"

namespace cf {

struct SurgeryUndo;

class VertexAdjacency {
 public:
  struct Out {
    int to;         // neighbour vertex id
    int halfedge;   // id of the halfedge from the vertex to `to`
    double length;  // (p_to - p_from).norm()
  };
  struct Range {
    const Out* first;
    const Out* last;
    const Out* begin() const { return first; }
    const Out* end() const { return last; }
  };

  VertexAdjacency() = default;
  explicit VertexAdjacency(const Mesh& mesh) { build(mesh); }
  // Every vertex's list from the mesh as it is. With run_both: the lists of the first and second
  // half of the vertices are written beside each other (the same block, entry for entry).
  void build(const Mesh& mesh, const RunBoth& run_both = {});
  // The lists of `vertices` (ids; those >= the mesh's vertex count are skipped) and of every vertex
  // added since the last build/refresh written again; vertices removed since are dropped.
  void refresh(const Mesh& mesh, const std::vector<int>& vertices);
  Range out(int v) const {
    const auto [b, e] = span_[std::size_t(v)];
    return Range{out_.data() + b, out_.data() + e};
  }
  // v's list as [first, last) indices into entries() (for callers that keep them per vertex).
  std::pair<std::uint32_t, std::uint32_t> span(int v) const { return span_[std::size_t(v)]; }
  const Out* entries() const { return out_.data(); }
  std::size_t vertices() const { return span_.size(); }
  // Entries stored, stale ones (lists written again since) included.
  std::size_t stored() const { return out_.size(); }

 private:
  void append(const Mesh& mesh, int v);
  bool fill(const Mesh& mesh, std::size_t from, std::size_t to);
  // Sized without writing (the entries are written once, by the thread that fills them).
  std::vector<Out, DefaultInitAllocator<std::allocator<Out>>> out_;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> span_;  // per vertex: [begin, end) in out_
  std::size_t live_ = 0;                                        // entries of the current lists
};

// The vertices whose list (outgoing halfedges, their order, to-vertices or edge lengths) the
// surgery that returned `undo` may have changed, taken on the mesh right after that surgery: its
// new vertices, the ends of its new halfedges and of every halfedge it repointed or relinked,
// the vertices of its new faces, the vertices whose outgoing halfedge it set, and the vertices it
// moved with their neighbours. The same set covers the undo of that surgery.
std::vector<int> touched_by_surgery(const Mesh& mesh, const SurgeryUndo& undo);

}  // namespace cf
