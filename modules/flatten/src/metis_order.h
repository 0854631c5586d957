// Nested dissection order of a symmetric system computed on two threads: one METIS vertex
// separator of the whole graph, then METIS_NodeND of its two sides side by side (libmetis 5.1,
// docs/flatten.md, "The METIS order split at the top separator").
#pragma once

#include <Eigen/SparseCore>

#include <array>
#include <cstdint>
#include <vector>

namespace cf::flat_detail {

using MetisSpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

// A graph in METIS's CSR form: vertex v's neighbours are adjncy[xadj[v] .. xadj[v + 1]), ascending,
// no self loop, each edge in both lists.
struct VertexGraph {
  std::vector<int> xadj{0}, adjncy;
  int size() const { return int(xadj.size()) - 1; }
};

// The vertex graph of a triangle surface with nv vertices (every corner < nv): the graph of its unit
// Laplacian, as graph_of builds it from that matrix, built from the corners alone (no edge list, no
// matrix: it can start before the surface's edges are built).
VertexGraph vertex_graph(const std::vector<std::array<int, 3>>& t, int nv);

// Whether this build calls METIS directly (libmetis-dev and CHOLMOD found by CMake).
bool metis_direct_available();

// The order before its postorder: side 0's vertices (METIS_NodeND of side 0's subgraph), then
// side 1's, then the `separator` vertices of METIS_ComputeVertexSeparator (ascending ids).
// order: place -> unknown, a permutation of 0..n-1; empty when METIS is missing or fails.
struct SplitOrder {
  std::vector<int> order;
  int first_side = 0;  // side 0's vertices, at the start of `order`
  int separator = 0;   // separator vertices, at the end of `order`
};

// A: n x n, symmetric, lower triangle stored, compressed, int indices; the diagonal is ignored.
// The two sides are ordered by cf::parallel_tasks (one thread each when thread_count() >= 2).
// The result does not depend on the thread count or the timing: every METIS call re-seeds, and
// libmetis's rand()/srand() reach this library's per-thread generator (metis_rand_calls()).
SplitOrder metis_split_order(const MetisSpMat& A);

// metis_split_order followed by the postorder of the elimination tree of A permuted by it (as
// cholmod_metis postorders: the same fill, each subtree's columns contiguous). place -> unknown;
// empty when METIS or CHOLMOD is missing or fails.
std::vector<int> metis_split_dissection_order(const MetisSpMat& A);
// The same order of the graph itself (the postorder from its lower triangle): for a surface's
// vertex_graph, the order of its unit Laplacian element for element (g: moved in, METIS's calls
// take non-const arrays).
std::vector<int> metis_split_dissection_order(VertexGraph g);

// How many times rand() has been answered by this library's generator on the calling thread:
// non-zero after a METIS call on this thread proves libmetis's rand() calls reach it and not the C
// library's one shared state.
std::uint64_t metis_rand_calls();

}  // namespace cf::flat_detail
