#pragma once
// The rows above the threaded factorisation's parts (the "rest", factor_schedule.h) computed in
// blocks that any number of threads can share, instead of cholmod_rowfac's one serial row after
// another. CHOLMOD builds only.
//
// Block form: P = the rows outside the rest (all computed), R = the rest (ascending, closed under
// ancestors in the elimination tree, so no row of P is an ancestor of one of R and L(P, R) = 0).
// Ordered [P, R] the factor is block lower triangular:
//   L_PP D_P L_PP^T = A_PP,   L_RP = A_RP L_PP^-T D_P^-1,   L_RR D_R L_RR^T = S = A_RR - L_RP D_P L_RP^T.
// 1. Row k of R: L(k, P)^T = (L_PP D_P)^-1 A(P, k), one sparse solve per row (cholmod_solve2,
//    CHOLMOD_LD, Bset = A(P, k)'s pattern) on the factor whose R columns are still the identity:
//    bit for bit the entries cholmod_rowfac writes (measured, docs/flatten.md session 25), and
//    independent per row, so the rows are split over the threads in any way.
// 2. S (dense |R| x |R|, lower triangle) = A_RR minus the rank-one terms d_j l_j l_j^T of every
//    column j of P (l_j = L(R, j)), each entry's terms subtracted in ascending j whoever computes it:
//    the threads own disjoint columns of S, so S has the same bits for any thread count.
// 3. S factorised by Eigen's dense LLT (blocked; never a hand-written solver), L_RR = its factor with
//    unit diagonal and D_R its diagonal squared, copied into L following L's symbolic pattern (row k's
//    columns in R: the tree paths from A's column k up to k, entries that are structurally zero in a
//    dense factor are exactly 0 there).
// The rest's entries differ from cholmod_rowfac's at rounding level (other partial sums); the factor
// is the same bits for every thread count (the caller takes this path by a rule that does not
// depend on it).
#ifdef COLONFLAT_HAVE_CHOLMOD
#include <cholmod.h>

#include <cstddef>
#include <vector>

namespace cf::flat_detail {

// Wall seconds of the three blocks and what they held (COLONFLAT_FLATTEN_DEBUG).
struct RestBlockWall {
  double solves = 0;   // step 1 (the rows' solves side by side) and the pattern of their R columns
  double copy = 0;     // L(R, P) appended to L's columns of P
  double schur = 0;    // step 2
  double root = 0;     // step 3 (dense LLT and the copy into L's columns of R)
  std::size_t rows = 0, entries_from_parts = 0;  // |R|, nnz(L_RP)
};

// The rows `rest` of the numeric simplicial LDL^T `L` computed by blocks (above), on up to
// thread_count() threads. `upper` = triu(A(p,p)) with values (cholmod_ptranspose of A in L's order),
// `parent` its elimination tree (factor_schedule.h). Pre: L->is_ll 0, every column has room for its
// column count; every row outside `rest` computed by cholmod_rowfac, none of `rest` (their columns
// the identity); `rest` ascending, closed under ancestors. Post (true): L is the factor of A,
// L->minor = n. False: the Schur complement is not positive definite (L's rest then unusable; the
// caller falls back). `wall` (optional): the blocks' wall seconds.
bool factor_rest_in_blocks(cholmod_sparse* upper, const std::vector<int>& parent, const std::vector<int>& rest,
                           cholmod_factor* L, RestBlockWall* wall = nullptr);

}  // namespace cf::flat_detail
#endif
