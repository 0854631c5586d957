// SpdSolver: CHOLMOD's simplicial LDL^T with a given or AMD elimination order; Eigen's
// SimplicialLDLT without CHOLMOD or when CHOLMOD fails (see spd_solver.h).
#include "spd_solver.h"

#include <sys/mman.h>

#include <cstdint>
#include <cstdlib>
#include <mutex>

#include "colonflat/core/error.h"

namespace cf::flat_detail {

#ifdef COLONFLAT_HAVE_CHOLMOD
namespace {

// CHOLMOD's large blocks (a colon's factor: about 300 MB) on transparent huge pages where the
// system allows them: faulting them in as 4 KiB pages cost about a tenth of the flatten time.
void advise_huge_pages(void* p, std::size_t bytes) {
  constexpr std::uintptr_t kHuge = std::uintptr_t(2) << 20;
  if (!p || bytes < 2 * kHuge) return;
  const std::uintptr_t first = (reinterpret_cast<std::uintptr_t>(p) + kHuge - 1) & ~(kHuge - 1);
  const std::uintptr_t last = (reinterpret_cast<std::uintptr_t>(p) + bytes) & ~(kHuge - 1);
#ifdef MADV_HUGEPAGE
  if (last > first) ::madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE);  // advice only
#endif
}
void* huge_malloc(std::size_t bytes) {
  void* p = std::malloc(bytes);
  advise_huge_pages(p, bytes);
  return p;
}
void* huge_calloc(std::size_t n, std::size_t size) {
  void* p = std::calloc(n, size);
  advise_huge_pages(p, n * size);
  return p;
}
void* huge_realloc(void* old, std::size_t bytes) {
  void* p = std::realloc(old, bytes);
  advise_huge_pages(p, bytes);
  return p;
}
void use_huge_pages_for_cholmod() {
  static std::once_flag once;
  std::call_once(once, [] {
    SuiteSparse_config.malloc_func = huge_malloc;
    SuiteSparse_config.calloc_func = huge_calloc;
    SuiteSparse_config.realloc_func = huge_realloc;
    SuiteSparse_config.free_func = std::free;
  });
}

// A read-only CHOLMOD view of the lower triangle of a compressed Eigen matrix.
cholmod_sparse view_lower(const SpdSolver::SpMat& A) {
  cholmod_sparse m{};
  m.nrow = m.ncol = std::size_t(A.rows());
  m.nzmax = std::size_t(A.nonZeros());
  m.p = const_cast<int*>(A.outerIndexPtr());
  m.i = const_cast<int*>(A.innerIndexPtr());
  m.x = const_cast<double*>(A.valuePtr());
  m.stype = -1;  // symmetric, lower triangle used
  m.itype = CHOLMOD_INT;
  m.xtype = CHOLMOD_REAL;
  m.dtype = CHOLMOD_DOUBLE;
  m.sorted = 1;
  m.packed = 1;
  return m;
}

}  // namespace

void SpdSolver::release() {
  if (factor_) cholmod_free_factor(&factor_, &common_);
  if (started_) cholmod_finish(&common_);
  started_ = false;
  cholmod_ok_ = false;
}

void SpdSolver::analyze(const SpMat& A, const std::vector<int>* order) {
  release();
  ldlt_.reset();
  use_huge_pages_for_cholmod();
  cholmod_start(&common_);
  started_ = true;
  common_.supernodal = CHOLMOD_SIMPLICIAL;
  common_.final_asis = 1;  // keep LDL^T
  cholmod_sparse view = view_lower(A);
  if (order && order->size() == std::size_t(A.rows())) {
    common_.nmethods = 1;
    common_.method[0].ordering = CHOLMOD_GIVEN;
    factor_ = cholmod_analyze_p(&view, const_cast<int*>(order->data()), nullptr, 0, &common_);
  } else {
    factor_ = cholmod_analyze(&view, &common_);
  }
}

bool SpdSolver::factorize(const SpMat& A) {
  if (factor_) {
    cholmod_sparse view = view_lower(A);
    cholmod_factorize(&view, factor_, &common_);
    cholmod_ok_ = common_.status >= CHOLMOD_OK && factor_->minor == factor_->n;
    if (cholmod_ok_) return true;
  }
  ldlt_ = std::make_unique<Eigen::SimplicialLDLT<SpMat>>();
  ldlt_->compute(A);
  return ldlt_->info() == Eigen::Success;
}

Eigen::MatrixXd SpdSolver::solve(const Eigen::MatrixXd& b) const {
  if (!cholmod_ok_) return ldlt_->solve(b);
  cholmod_dense rhs{};
  rhs.nrow = std::size_t(b.rows());
  rhs.ncol = std::size_t(b.cols());
  rhs.nzmax = rhs.d = rhs.nrow;
  rhs.x = const_cast<double*>(b.data());
  rhs.xtype = CHOLMOD_REAL;
  rhs.dtype = CHOLMOD_DOUBLE;
  cholmod_dense* x = cholmod_solve(CHOLMOD_A, factor_, &rhs, &common_);
  if (!x) throw Error("sparse solve failed (CHOLMOD status " + std::to_string(common_.status) + ")");
  Eigen::MatrixXd out = Eigen::Map<const Eigen::MatrixXd>(static_cast<const double*>(x->x), b.rows(), b.cols());
  cholmod_free_dense(&x, &common_);
  return out;
}

std::vector<int> SpdSolver::order() const {
  if (!factor_ || !factor_->Perm) return {};
  const int* perm = static_cast<const int*>(factor_->Perm);
  return std::vector<int>(perm, perm + factor_->n);
}

#else  // Eigen only: the order is Eigen's AMD, a given one is not used

void SpdSolver::release() {}

void SpdSolver::analyze(const SpMat& A, const std::vector<int>*) {
  ldlt_ = std::make_unique<Eigen::SimplicialLDLT<SpMat>>();
  ldlt_->analyzePattern(A);
}

bool SpdSolver::factorize(const SpMat& A) {
  if (!ldlt_) analyze(A);
  ldlt_->factorize(A);
  return ldlt_->info() == Eigen::Success;
}

Eigen::MatrixXd SpdSolver::solve(const Eigen::MatrixXd& b) const { return ldlt_->solve(b); }

std::vector<int> SpdSolver::order() const { return {}; }

#endif

}  // namespace cf::flat_detail
