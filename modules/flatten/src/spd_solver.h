#pragma once
// Sparse symmetric positive definite solve for the flatten stage: CHOLMOD's simplicial LDL^T
// (SuiteSparse) when the build found it, Eigen's SimplicialLDLT otherwise, and as the fallback
// when CHOLMOD fails.
//
// Simplicial, not supernodal: on the surface Laplacians here (2D graphs, about 40 nonzeros of L
// per row) the supernodal factorisation with the reference BLAS was 1.7x slower (5.7 s against
// 3.3 s for 0.69 M unknowns) and spent its time in OpenMP start-up and in zeroing a larger factor
// (with OpenBLAS it was no faster: 4.8 s, session 7).
//
// The fill-reducing ordering (AMD) costs about a third of a factorisation; a caller that solves
// several systems on (subsets of) the same graph computes it once: analyze() takes an elimination
// order (fill_reducing_order() gives AMD's), and order() gives the one used. An order of a graph
// restricted to a subset of its vertices (relative order kept) is a valid ordering of the subgraph
// with no more fill than the original (docs/flatten.md, "Speed").
//
// Threads: from 20 000 unknowns on, the numeric factorisation computes its rows on the worker
// threads (threaded_factor.h, factor_schedule.h: two parts of whole elimination subtrees side by
// side, the rows above them split again in phases, then the last rows, in blocks shared by the
// threads when they are many, rest_blocks.h); the factor is the same bits for every thread count
// (bit for bit cholmod_factorize's when the last rows are not in blocks), so nothing depends on it.
//
// Leading block: with a given order, the factor of P A P^T = L D L^T holds the factor of the
// leading k x k block A_II (I: the first k unknowns of the order) as its top-left corner, so
// solve_leading() solves A_II x_I = b_I with the same factorisation. The conformal map uses it to
// solve u (Dirichlet on both ends: the ends' vertices ordered last) with the factor of v's system.
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <atomic>
#include <memory>
#include <mutex>
#include <vector>

#ifdef COLONFLAT_HAVE_CHOLMOD
#include <cholmod.h>
#endif

#include "factor_schedule.h"
#include "threaded_factor.h"

namespace cf::flat_detail {

class TreeSolve;

class SpdSolver {
 public:
  using SpMat = Eigen::SparseMatrix<double>;
  SpdSolver();
  SpdSolver(const SpdSolver&) = delete;
  SpdSolver& operator=(const SpdSolver&) = delete;
  ~SpdSolver();

  // AMD's fill-reducing elimination order of A (n x n, symmetric, compressed, lower triangle
  // read): order[k] = the unknown eliminated k-th.
  static std::vector<int> fill_reducing_order(const SpMat& A);
  // Nested dissection's (METIS, through CHOLMOD) elimination order of A (as above): on a colon band
  // about half the factorisation's operations of AMD's order, for about 5 x AMD's ordering time
  // (docs/flatten.md, "Speed", session 13). Split at METIS's top vertex separator, its two sides
  // ordered on two threads (metis_order.h) when libmetis-dev is there, else cholmod_metis's one
  // call; AMD's order when CHOLMOD or METIS is not there.
  static std::vector<int> nested_dissection_order(const SpMat& A);
  // Floating-point operations of the numeric factorisation of A (as above) in the elimination order
  // `order` (a permutation of 0..n-1, used as given): CHOLMOD's count from a symbolic analysis alone
  // (no schedule, no numeric work; the count factor_flops() gives after analyze(A, &order)). 0
  // without CHOLMOD or when the analysis fails.
  static double order_flops(const SpMat& A, const std::vector<int>& order);
  // cholmod_metis's one-call METIS order of A (METIS's defaults, postordered; what
  // nested_dissection_order was before the split); empty without CHOLMOD or when it fails.
  static std::vector<int> one_call_dissection_order(const SpMat& A);
  // Symbolic analysis of A (lower triangle read). `order` (optional): the elimination order, a
  // permutation of 0..n-1 used as given (not postordered); AMD (CHOLMOD's default) when null.
  void analyze(const SpMat& A, const std::vector<int>* order = nullptr);
  // Numeric factorisation of A (same pattern as analyzed); false when no factorisation succeeded.
  bool factorize(const SpMat& A);
  // analyze(A, order) then factorize(A). With a given order on two or more threads the numeric
  // transpose triu(A(p,p)) the threaded factorisation starts from is made beside the symbolic
  // analysis, with the row schedule (A's values are known to be the ones factorised); analyze()
  // alone makes only the pattern's, since factorize() may be given other values.
  bool compute(const SpMat& A, const std::vector<int>* order = nullptr);
  // x = A^-1 b (b: n x k), kColumnsPerSolveCall columns per CHOLMOD call: the groups on the worker
  // threads when the factor has at least kThreadedSolveMinEntries entries and there are two or more,
  // else one after the other on the calling thread. One group (k <= 3) of such a factor on two or
  // more threads is solved by TreeSolve (tree_solve.h: L's elimination tree split over two threads)
  // from the factor's kTreeSolveFrom-th such solve on (its plan, made then, costs about one solve
  // and is kept until the factor changes). A column's result is
  // the same bits every way (those of its one-column CHOLMOD solve).
  Eigen::MatrixXd solve(const Eigen::MatrixXd& b) const;
  // Columns one CHOLMOD solve call takes: its simplicial kernels for 2 and 3 right-hand sides read L
  // once for all of them (a solve is bound by reading L, ~12 bytes an entry) and compute each column
  // with the one-column kernel's operations (bitwise equal, tested); its 4-column kernel does not.
  // A 2-column solve of a 1.3e7-entry factor: 0.041-0.044 CPU s against 0.065-0.066 for two calls
  // (docs/flatten.md, session 24).
  static constexpr Eigen::Index kColumnsPerSolveCall = 3;
  // CHOLMOD solve calls solve() has made on this solver (each reads L once).
  int solve_calls() const { return solve_calls_.load(); }
  // A column's solve reads L twice (about 24 bytes an entry): at 10^6 entries some 10 ms (an
  // estimate at a few GB/s), far above what starting a thread for it costs (tens of microseconds
  // idle; on a loaded machine the new thread also waits for a core). The local area-correction
  // pieces (a few thousand unknowns, 10^4-10^5 entries) solve hundreds to thousands of times each:
  // the real CT colon band's longest piece, 1 248 solves, 1.64 s -> 0.46 s wall at load 11-14
  // (docs/flatten.md, session 15). 2 x 10^5 since session 34 ("idle"): the CT mask's lone window piece
  // of the last local pass (30 k unknowns, below 10^6 entries) solved on one thread, 196 steps, the other
  // core idle (its pass 1.78 -> 1.59 s wall, piece 1.47 -> 1.27 s at load 3; same bits: TreeSolve's).
  static constexpr std::size_t kThreadedSolveMinEntries = 200000;
  // The first solve of a factor is CHOLMOD's (a factor solved once, as the conformal maps' v, does
  // not pay for a plan: 0.03 s on 1e7 entries, 0.08-0.4 s on 2.6e7 at load 10); from the second on
  // TreeSolve's (the whole-band pass solves its factor once a step, 3-60 steps).
  static constexpr int kTreeSolveFrom = 2;
  // Entries the numeric factor holds (0 without CHOLMOD or before factorize()).
  std::size_t factor_entries() const;
  // Columns of the factor's dense root: the last columns j of L that are full below the diagonal
  // (n - j entries with the diagonal), one clique at the top of the elimination tree that no two
  // threads can share (factor_schedule.h: its rows are the rest). 0 without CHOLMOD or before analyze().
  int dense_root_columns() const;
  // x_I = A_II^-1 b_I for I = the first `leading` unknowns of the order given to analyze(), and
  // x = 0 off I (b's entries off I are not read). Throws Error without a given order.
  Eigen::MatrixXd solve_leading(const Eigen::MatrixXd& b, int leading) const;
  // The factorisation of A + C C^T (`update`) or A - C C^T (C: n x k, rows = unknowns), modified in
  // place (CHOLMOD's update/downdate: the cost of the columns of L it touches, not of a new
  // factorisation). False without CHOLMOD or when the result is not positive definite; the solver
  // is then unusable until factorize().
  bool modify(const SpMat& C, bool update);
  // Floating-point operations of the numeric factorisation (CHOLMOD's count from the analysis; 0
  // without CHOLMOD or before analyze()).
  double factor_flops() const;
  // Estimated operations of modify() with the columns of each matrix of `terms`: per column, 4 x the
  // entries of L on the elimination-tree path from its first row (in the factor's order) to the
  // root (the columns a rank-one update changes; Davis & Hager 1999). Counting stops past `limit`.
  double modify_flops(const std::vector<const SpMat*>& terms, double limit) const;
  // The elimination order of the analysis (empty without CHOLMOD or before analyze()).
  std::vector<int> order() const;
  // Whether the last factorize() split its rows over the threads by the schedule computed beside
  // the symbolic analysis of a given order (analyze() on two threads: CHOLMOD's analysis and the
  // schedule, both reading only A's pattern in that order), not one computed after it.
  bool early_schedule() const { return early_schedule_; }
  // Whether the last factorize() started from the numeric transpose made beside the analysis
  // (compute() with a given order on threads), and how many numeric transposes this solver's
  // threaded factorisations have made themselves (not counting those made beside an analysis).
  bool early_transpose() const { return early_transpose_; }
  // Whether the last factorize() computed the rows above the threaded parts in blocks (rest_blocks.h).
  bool rest_blocks() const { return rest_blocks_; }
  int threaded_transposes() const { return threaded_transposes_; }
  // Solves of this factor that TreeSolve computed (each counted in solve_calls() too).
  int tree_solves() const { return tree_solves_.load(); }

 private:
  struct Fallback;  // Eigen's SimplicialLDLT of P A P^T, P the given order (else Eigen's AMD)
  void release();
  void release_early();  // the schedule and transpose made beside the analysis, once used or stale
  void analyze_for(const SpMat& A, const std::vector<int>* order, bool numeric_transpose);
  bool fall_back(const SpMat& A);
  std::vector<int> given_order_;
  FactorPlan schedule_;  // from analyze(), for the next factorize() (empty phases: none)
  bool early_schedule_ = false, early_transpose_ = false, rest_blocks_ = false;
  int threaded_transposes_ = 0;
  mutable std::atomic<int> solve_calls_{0};  // solve()'s CHOLMOD calls (solve() may run on two threads at once)
  mutable std::atomic<int> tree_solves_{0};
  mutable std::atomic<int> group_solves_{0};  // one-group solves of this factor that could take TreeSolve
  mutable std::mutex tree_mutex_;            // the plan is made once, by the first solve() that needs it
  mutable std::shared_ptr<const TreeSolve> tree_;  // of factor_ as it is now (null: not made yet)
  std::shared_ptr<const TreeSolve> tree_plan() const;
  Eigen::MatrixXd tree_solve(const TreeSolve& plan, const Eigen::MatrixXd& b) const;
#ifdef COLONFLAT_HAVE_CHOLMOD
  mutable cholmod_common common_{};
  bool started_ = false;
  cholmod_factor* factor_ = nullptr;
  ThreadCommon side_;                       // allocates early_upper_ beside the analysis, and frees it
  cholmod_sparse* early_upper_ = nullptr;   // numeric triu(A(p,p)) from compute(), for its factorize()
  bool cholmod_ok_ = false;
  Eigen::MatrixXd cholmod_leading(const Eigen::MatrixXd& b, int leading) const;

 public:
  // CHOLMOD's factor (read only; null before analyze()).
  const cholmod_factor* factor() const { return factor_; }
#endif
  std::unique_ptr<Fallback> fallback_;
};

#ifdef COLONFLAT_HAVE_CHOLMOD
// A read-only CHOLMOD view of the lower triangle of a compressed A (stype -1, no copy: valid while
// A lives and is not changed).
cholmod_sparse view_lower(const SpdSolver::SpMat& A);
// A read-only CHOLMOD view of nrow x ncol compressed columns (p: ncol + 1 column starts, i: sorted
// row indices, x: values, or null for a pattern; no copy); stype -1: symmetric, lower triangle used;
// 0: unsymmetric.
cholmod_sparse view_columns(std::size_t nrow, std::size_t ncol, const int* p, const int* i, const double* x, int stype);
#endif

}  // namespace cf::flat_detail
