#pragma once
// Z2 homology of a surface mesh, from a tree-cotree decomposition (Eppstein; Erickson-Whittlesey).
//
// Each boundary loop is closed by a virtual polygon face, so the classes are those of the closed
// surface M^ = M + disks; an edge cycle of M is non-separating in M exactly when its class in
// H1(M^; Z2) is nonzero (equivalently: nonzero in H1(M, dM; Z2)).
//
// build() computes, per component: a spanning tree D of the dual graph (faces and virtual faces,
// breadth-first from the component's first face), the cut graph G = primal edges not dual to D
// (Algorithm 1 of the seed paper), a spanning tree T of G and the 2g leftover edges X. Each edge
// gets an annotation a(e) in Z2^(2G), G = total genus: unit vectors on X, zero on T, and on the
// dual-tree edges the value that makes every face's boundary sum to zero (leaf peeling). The
// class of any edge cycle is the XOR of its edges' annotations.
//
// Storage: most annotations are zero (a dual-tree edge carries a bit only when it lies on the
// dual-tree paths joining the two faces of that bit's X edge, which share most of their length
// near the root), so each edge holds an index into a pool of its nonzero class rows (row 0 is
// the zero class) instead of a dense edges x words table (188 MB at 2.3 M edges and genus 300).
#include <cstdint>
#include <utility>
#include <vector>

#include "colonflat/core/mesh.h"
#include "colonflat/denoise/run_both.h"

namespace cf {

namespace detail {
struct ClosedDual;  // the dual graph with one virtual face per boundary loop (homology.cpp)
}

class HomologyBasis {
 public:
  // Precondition: `mesh` is a manifold (garbage-collected) triangle mesh. With `run_both`, the
  // pruning of the cut graph runs on the helper beside the annotations (both need only the dual
  // forest): the same result as one thread.
  void build(const Mesh& mesh, const RunBoth& run_both = {});
  // Builds whose pruning ran beside the annotations (on a helper through run_both).
  int builds_on_two_threads() const { return builds_on_two_threads_; }

  int rank() const { return rank_; }    // 2 * total genus = |X|
  int words() const { return words_; }  // 64-bit words per class vector
  // Class of edge e (`words()` words). Valid until the next set_edge_class() or build().
  const std::uint64_t* edge_class(Mesh::EdgeHandle e) const {
    const std::size_t e_id = static_cast<std::size_t>(e.idx());
    return &rows_[std::size_t(e_id < row_of_.size() ? row_of_[e_id] : 0) * words_];
  }
  bool edge_class_is_zero(Mesh::EdgeHandle e) const {
    const std::size_t e_id = static_cast<std::size_t>(e.idx());
    return e_id >= row_of_.size() || row_of_[e_id] == 0;
  }
  // Sets the class of an edge (also one created after build()). `cls` must not point into this
  // table (pass a copy).
  void set_edge_class(Mesh::EdgeHandle e, const std::uint64_t* cls);
  // Edges whose class is nonzero (statistics; the table's size in rows minus the zero row).
  std::size_t nonzero_rows() const { return rows_.size() / words_ - 1; }

  // Cut graph G (all its edges) and its pruned core (degree-1 vertices removed recursively), as
  // flags indexed by edge / vertex id of the mesh given to build().
  const std::vector<std::uint8_t>& cut_graph_edges() const { return cut_edge_; }
  const std::vector<std::uint8_t>& pruned_cut_graph_edges() const { return pruned_edge_; }
  std::vector<int> pruned_cut_graph_vertices() const;

 private:
  void annotate_edges(const Mesh& mesh, const detail::ClosedDual& dual, const std::vector<int>& parent_edge,
                      const std::vector<int>& order);
  void prune_cut_graph(const Mesh& mesh);
  // Removes degree-1 vertices of the cut graph (rows start / adjacent: per vertex its (cut edge,
  // other end)) until none is left; `degree` ends as each vertex's degree in the pruned graph.
  void peel_leaves(const std::vector<std::uint32_t>& start, const std::vector<std::pair<int, int>>& adjacent,
                   std::vector<int>& degree);
  std::uint32_t new_row(const std::uint64_t* cls);
  int rank_ = 0, words_ = 1, builds_on_two_threads_ = 0;
  std::vector<std::uint32_t> row_of_;  // per edge: its row in rows_ (0: the zero class)
  std::vector<std::uint64_t> rows_;    // class rows, words_ each; row 0 is zero
  std::vector<std::uint8_t> cut_edge_, pruned_edge_;
  std::vector<int> pruned_vertices_;
};

// A subspace of Z2^n kept in reduced echelon form (each pivot bit set in exactly one row).
class Z2Span {
 public:
  explicit Z2Span(int words = 1) : words_(words) {}
  void reset(int words) {
    words_ = words;
    rows_.clear();
    pivots_.clear();
  }
  int dimension() const { return static_cast<int>(pivots_.size()); }
  // Reduces v in place modulo the span; returns true if the result is zero (v in span).
  bool reduce(std::uint64_t* v) const;
  bool contains(const std::uint64_t* v) const;
  // Adds v; returns false if it was already in the span.
  bool insert(const std::uint64_t* v);

 private:
  int words_;
  std::vector<std::vector<std::uint64_t>> rows_;
  std::vector<int> pivots_;
};

inline bool is_zero(const std::uint64_t* v, int words) {
  for (int i = 0; i < words; ++i)
    if (v[i]) return false;
  return true;
}
inline void xor_into(std::uint64_t* dst, const std::uint64_t* src, int words) {
  for (int i = 0; i < words; ++i) dst[i] ^= src[i];
}

}  // namespace cf
