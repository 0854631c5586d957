#pragma once
// Sparse symmetric positive definite solve for the flatten stage: CHOLMOD's supernodal Cholesky
// (SuiteSparse, through Eigen's CholmodSupport) when the build found it, several times faster
// than Eigen's SimplicialLDLT on large Laplacians; SimplicialLDLT otherwise, and as the fallback
// when the LLT factorisation fails (a not quite positive definite matrix).
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <memory>

#ifdef COLONFLAT_HAVE_CHOLMOD
#include <Eigen/CholmodSupport>
#endif

namespace cf::flat_detail {

class SpdSolver {
 public:
  using SpMat = Eigen::SparseMatrix<double>;
  // Factorises A; false when no factorisation succeeded.
  bool compute(const SpMat& A) {
#ifdef COLONFLAT_HAVE_CHOLMOD
    llt_ = std::make_unique<Eigen::CholmodSupernodalLLT<SpMat>>();
    llt_->compute(A);
    if (llt_->info() == Eigen::Success) return true;
    llt_.reset();
#endif
    ldlt_ = std::make_unique<Eigen::SimplicialLDLT<SpMat>>();
    ldlt_->compute(A);
    return ldlt_->info() == Eigen::Success;
  }
  Eigen::MatrixXd solve(const Eigen::MatrixXd& b) const {
#ifdef COLONFLAT_HAVE_CHOLMOD
    if (llt_) return llt_->solve(b);
#endif
    return ldlt_->solve(b);
  }

 private:
#ifdef COLONFLAT_HAVE_CHOLMOD
  std::unique_ptr<Eigen::CholmodSupernodalLLT<SpMat>> llt_;
#endif
  std::unique_ptr<Eigen::SimplicialLDLT<SpMat>> ldlt_;
};

}  // namespace cf::flat_detail
