#pragma once
// Sparse symmetric positive definite solve for the flatten stage: CHOLMOD's simplicial LDL^T
// (SuiteSparse) when the build found it, Eigen's SimplicialLDLT otherwise, and as the fallback
// when CHOLMOD fails.
//
// Simplicial, not supernodal: on the surface Laplacians here (2D graphs, about 40 nonzeros of L
// per row) the supernodal factorisation with the reference BLAS was 1.7x slower (5.7 s against
// 3.3 s for 0.69 M unknowns) and spent its time in OpenMP start-up and in zeroing a larger factor.
//
// The fill-reducing ordering (AMD) costs about a third of a factorisation; a caller that solves
// several systems on (subsets of) the same graph computes it once: analyze() takes an elimination
// order, and order() gives the one used. An order of a graph restricted to a subset of its
// vertices (relative order kept) is a valid ordering of the subgraph with no more fill than the
// original (docs/flatten.md, "Speed").
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <memory>
#include <vector>

#ifdef COLONFLAT_HAVE_CHOLMOD
#include <cholmod.h>
#endif

namespace cf::flat_detail {

class SpdSolver {
 public:
  using SpMat = Eigen::SparseMatrix<double>;
  SpdSolver() = default;
  SpdSolver(const SpdSolver&) = delete;
  SpdSolver& operator=(const SpdSolver&) = delete;
  ~SpdSolver() { release(); }

  // Symbolic analysis of A (n x n, symmetric, compressed; its lower triangle is read).
  // `order` (optional): the elimination order, a permutation of 0..n-1 (order[k] = the unknown
  // eliminated k-th); AMD (CHOLMOD's default choice) when null.
  void analyze(const SpMat& A, const std::vector<int>* order = nullptr);
  // Numeric factorisation of A (same pattern as analyzed); false when no factorisation succeeded.
  bool factorize(const SpMat& A);
  bool compute(const SpMat& A, const std::vector<int>* order = nullptr) {
    analyze(A, order);
    return factorize(A);
  }
  // x = A^-1 b (b: n x k).
  Eigen::MatrixXd solve(const Eigen::MatrixXd& b) const;
  // The elimination order of the analysis (empty without CHOLMOD or before analyze()).
  std::vector<int> order() const;

 private:
  void release();
#ifdef COLONFLAT_HAVE_CHOLMOD
  mutable cholmod_common common_{};
  bool started_ = false;
  cholmod_factor* factor_ = nullptr;
  bool cholmod_ok_ = false;
#endif
  std::unique_ptr<Eigen::SimplicialLDLT<SpMat>> ldlt_;
};

}  // namespace cf::flat_detail
