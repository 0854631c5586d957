// Nested dissection order of a symmetric system computed on two threads: one METIS vertex
// separator of the whole graph, a large side split again at its own, then METIS_NodeND of the parts
// side by side (libmetis 5.1, docs/flatten.md, "The METIS order split at the top separator").
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

// A side of the top separator with at least this many vertices is split again at its own METIS
// vertex separator and its two halves are ordered by METIS_NodeND: on a colon band four parts of
// about a quarter each instead of two of about half, which two threads end at about the same time
// (the real CT colon's sides, 457 k and 603 k vertices, took 2.24 and 3.02 CPU s; its four parts
// 1.66 / 1.18 / 1.08 / 0.81: the first map's system waited 1.56 s for the order, one core idle for
// 1.0 s of it; issue 26, session 31). From 420 000 on: the bands of about 2 M faces (the real CT's
// and its mask's rows, flatten 21-24 s against the 20 s goal); the real mask's rows (sides of at
// most 0.41 M vertices, flatten 8-10 s) keep their order and their maps bit for bit (with 200 000
// their maps moved by rounding: the grown real mask's 99.683 % shown became 99.669 %).
constexpr int kSplitSidesMinVertices = 420000;

// The order before its postorder: side 0's vertices, then side 1's, then the `separator` vertices
// of METIS_ComputeVertexSeparator (ascending ids). A side is ordered by METIS_NodeND of its
// subgraph, or (from split_sides_from vertices on) as its two halves' METIS_NodeND orders, one after
// the other, then its own separator's vertices (ascending ids).
// order: place -> unknown, a permutation of 0..n-1; empty when METIS is missing or fails.
struct SplitOrder {
  std::vector<int> order;
  int first_side = 0;  // side 0's vertices, at the start of `order`
  int separator = 0;   // separator vertices, at the end of `order`
  // [begin, end) in `order` of each part METIS_NodeND ordered (side 0's, then side 1's); the places
  // in no part hold separator vertices.
  std::vector<std::array<int, 2>> parts;
};

// A: n x n, symmetric, lower triangle stored, compressed, int indices; the diagonal is ignored.
// The sides are built (and split) and then the parts ordered by cf::parallel_tasks, the largest
// part first. The result does not depend on the thread count or the timing: every METIS call
// re-seeds, and libmetis's rand()/srand() reach this library's per-thread generator (metis_rand_calls()).
SplitOrder metis_split_order(const MetisSpMat& A, int split_sides_from = kSplitSidesMinVertices);

// metis_split_order followed by the postorder of the elimination tree of A permuted by it (as
// cholmod_metis postorders: the same fill, each subtree's columns contiguous). place -> unknown;
// empty when METIS or CHOLMOD is missing or fails.
std::vector<int> metis_split_dissection_order(const MetisSpMat& A, int split_sides_from = kSplitSidesMinVertices);
// The same order of the graph itself (the postorder from its lower triangle): for a surface's
// vertex_graph, the order of its unit Laplacian element for element (g: moved in, METIS's calls
// take non-const arrays).
std::vector<int> metis_split_dissection_order(VertexGraph g, int split_sides_from = kSplitSidesMinVertices);

// How many times rand() has been answered by this library's generator on the calling thread:
// non-zero after a METIS call on this thread proves libmetis's rand() calls reach it and not the C
// library's one shared state.
std::uint64_t metis_rand_calls();

}  // namespace cf::flat_detail
