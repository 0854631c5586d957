// SpdSolver: CHOLMOD's simplicial LDL^T with a given or AMD elimination order; Eigen's
// SimplicialLDLT without CHOLMOD or when CHOLMOD fails (see spd_solver.h).
#include "spd_solver.h"

#include <Eigen/OrderingMethods>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <mutex>

#include "colonflat/core/error.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/core/threads.h"
#include "factor_memory.h"
#include "factor_schedule.h"
#include "metis_order.h"
#include "threaded_factor.h"
#include "tree_solve.h"

namespace cf::flat_detail {

// Eigen's SimplicialLDLT of P A P^T with P the given elimination order (else Eigen's AMD), so that
// the leading block of the order is the factor's top-left corner here too.
struct SpdSolver::Fallback {
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> perm;  // unknown -> its place in the order
  Eigen::SimplicialLDLT<SpMat, Eigen::Lower, Eigen::NaturalOrdering<int>> ldlt;

  bool compute(const SpMat& A, const std::vector<int>& order) {
    const std::vector<int> used = order.size() == std::size_t(A.rows()) ? order : eigen_amd(A);
    perm.resize(A.rows());
    for (std::size_t k = 0; k < used.size(); ++k) perm.indices()[used[k]] = int(k);
    SpMat permuted;
    permuted = A.selfadjointView<Eigen::Lower>().twistedBy(perm);
    ldlt.compute(permuted);
    return ldlt.info() == Eigen::Success;
  }
  static std::vector<int> eigen_amd(const SpMat& A) {
    Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> inverse;  // place -> unknown
    Eigen::AMDOrdering<int>()(A, inverse);
    return std::vector<int>(inverse.indices().data(), inverse.indices().data() + inverse.size());
  }
  Eigen::MatrixXd solve(const Eigen::MatrixXd& b) const { return perm.transpose() * ldlt.solve(perm * b); }
  Eigen::MatrixXd solve_leading(const Eigen::MatrixXd& b, int leading) const {
    Eigen::MatrixXd y = perm * b;
    ldlt.matrixL().solveInPlace(y);
    y.bottomRows(y.rows() - leading).setZero();
    y = ldlt.vectorD().asDiagonal().inverse() * y;
    ldlt.matrixU().solveInPlace(y);
    return perm.transpose() * y;
  }
};

SpdSolver::SpdSolver() = default;
SpdSolver::~SpdSolver() { release(); }

bool SpdSolver::fall_back(const SpMat& A) {
  fallback_ = std::make_unique<Fallback>();
  return fallback_->compute(A, given_order_);
}

Eigen::MatrixXd SpdSolver::solve_leading(const Eigen::MatrixXd& b, int leading) const {
  if (given_order_.empty() || leading < 0 || leading > b.rows())
    throw Error("solve_leading needs the elimination order given to analyze()");
#ifdef COLONFLAT_HAVE_CHOLMOD
  if (cholmod_ok_) return cholmod_leading(b, leading);
#endif
  return fallback_->solve_leading(b, leading);
}

#ifdef COLONFLAT_HAVE_CHOLMOD
cholmod_sparse view_columns(std::size_t nrow, std::size_t ncol, const int* p, const int* i, const double* x, int stype) {
  cholmod_sparse m{};
  m.nrow = nrow;
  m.ncol = ncol;
  m.nzmax = std::max<std::size_t>(std::size_t(p[ncol]), 1);
  m.p = const_cast<int*>(p);
  m.i = const_cast<int*>(p[ncol] > 0 ? i : p);  // CHOLMOD wants a pointer even without entries
  m.x = const_cast<double*>(x);
  m.stype = stype;
  m.itype = CHOLMOD_INT;
  m.xtype = x ? CHOLMOD_REAL : CHOLMOD_PATTERN;
  m.dtype = CHOLMOD_DOUBLE;
  m.sorted = 1;
  m.packed = 1;
  return m;
}

cholmod_sparse view_lower(const SpdSolver::SpMat& A) {
  return view_columns(std::size_t(A.rows()), std::size_t(A.cols()), A.outerIndexPtr(), A.innerIndexPtr(), A.valuePtr(), -1);
}

namespace {

// A CHOLMOD view of a column-major Eigen matrix.
cholmod_dense view_dense(const Eigen::MatrixXd& b) {
  cholmod_dense d{};
  d.nrow = std::size_t(b.rows());
  d.ncol = std::size_t(b.cols());
  d.nzmax = d.nrow * d.ncol;
  d.d = d.nrow;
  d.x = const_cast<double*>(b.data());
  d.xtype = CHOLMOD_REAL;
  d.dtype = CHOLMOD_DOUBLE;
  return d;
}

Eigen::MatrixXd take_dense(cholmod_dense*& x, cholmod_common& common) {
  Eigen::MatrixXd out = Eigen::Map<const Eigen::MatrixXd>(static_cast<const double*>(x->x), Eigen::Index(x->nrow),
                                                          Eigen::Index(x->ncol));
  cholmod_free_dense(&x, &common);
  return out;
}

// METIS (libmetis 5.1 as packaged) draws its random numbers from the C library's rand(): one state
// for the process, re-seeded at each call. Two calls at once interleave their draws, and each order
// then depends on the timing (two large colon segments flattened side by side); one at a time, each
// is the order it is alone.
std::mutex& metis_mutex() {
  static std::mutex m;
  return m;
}

// CHOLMOD's AMD (`nested` false) or METIS nested dissection order of A; empty when it fails.
std::vector<int> cholmod_order(const SpdSolver::SpMat& A, bool nested) {
  install_for_cholmod();
  cholmod_common common;
  cholmod_start(&common);
  common.print = 0;
  cholmod_sparse view = view_lower(A);
  std::vector<int> order(std::size_t(A.rows()));
  std::unique_lock<std::mutex> one_metis_at_a_time(metis_mutex(), std::defer_lock);
  if (nested) one_metis_at_a_time.lock();
  const bool ok = nested ? cholmod_metis(&view, nullptr, 0, 1, order.data(), &common)
                         : cholmod_amd(&view, nullptr, 0, order.data(), &common);
  cholmod_finish(&common);
  return ok ? order : std::vector<int>();
}

}  // namespace

std::vector<int> SpdSolver::fill_reducing_order(const SpMat& A) {
  std::vector<int> order = cholmod_order(A, false);
  return order.empty() ? Fallback::eigen_amd(A) : order;
}

std::vector<int> SpdSolver::one_call_dissection_order(const SpMat& A) { return cholmod_order(A, true); }

double SpdSolver::order_flops(const SpMat& A, const std::vector<int>& order) {
  if (order.size() != std::size_t(A.rows())) return 0.0;
  install_for_cholmod();
  ThreadCommon common;
  common.c.supernodal = CHOLMOD_SIMPLICIAL;
  common.c.nmethods = 1;
  common.c.method[0].ordering = CHOLMOD_GIVEN;
  common.c.postorder = 0;
  cholmod_sparse view = view_lower(A);
  cholmod_factor* L = cholmod_analyze_p(&view, const_cast<int*>(order.data()), nullptr, 0, &common.c);
  const double flops = L ? common.c.fl : 0.0;
  if (L) cholmod_free_factor(&L, &common.c);
  return flops;
}

std::vector<int> SpdSolver::nested_dissection_order(const SpMat& A) {
  std::vector<int> order = metis_split_dissection_order(A);
  if (order.empty()) order = cholmod_order(A, true);
  return order.empty() ? fill_reducing_order(A) : order;
}

void SpdSolver::release_early() {
  schedule_.clear();
  if (early_upper_) cholmod_free_sparse(&early_upper_, &side_.c);
}

void SpdSolver::release() {
  release_early();
  tree_.reset();
  group_solves_ = 0;
  early_schedule_ = early_transpose_ = rest_blocks_ = false;
  if (factor_) cholmod_free_factor(&factor_, &common_);
  if (started_) cholmod_finish(&common_);
  started_ = false;
  cholmod_ok_ = false;
}

void SpdSolver::analyze(const SpMat& A, const std::vector<int>* order) { analyze_for(A, order, false); }

bool SpdSolver::compute(const SpMat& A, const std::vector<int>* order) {
  analyze_for(A, order, true);
  return factorize(A);
}

// analyze(); `numeric_transpose`: A is the matrix the next factorize() is given, so the threaded
// factorisation's transpose is made with its values beside the analysis (early_upper_).
void SpdSolver::analyze_for(const SpMat& A, const std::vector<int>* order, bool numeric_transpose) {
  release();
  fallback_.reset();
  given_order_.clear();
  install_for_cholmod();
  cholmod_start(&common_);
  common_.print = 0;  // no warnings on stderr: a failed factorisation is reported by status and falls back
  started_ = true;
  common_.supernodal = CHOLMOD_SIMPLICIAL;
  common_.final_asis = 1;  // keep LDL^T
  cholmod_sparse view = view_lower(A);
  if (order && order->size() == std::size_t(A.rows())) {
    common_.nmethods = 1;
    common_.method[0].ordering = CHOLMOD_GIVEN;
    common_.postorder = 0;  // the order as given: its leading block stays the factor's top-left corner
    double seconds[2] = {0, 0};  // wall of the analysis and of the schedule (debug)
    const auto symbolic = [&] {
      const Stopwatch sw;
      factor_ = cholmod_analyze_p(&view, const_cast<int*>(order->data()), nullptr, 0, &common_);
      seconds[0] = sw.seconds();
    };
    // The threaded factorisation's row schedule reads only the pattern of A in this order: computed
    // on a second thread beside CHOLMOD's analysis instead of after it, in factorize().
    if (thread_count() > 1 && std::size_t(A.rows()) >= kThreadedFactorMinRows)
      parallel_tasks({symbolic, [&] {
                        const Stopwatch sw;
                        EarlyRows early = early_rows(&view, *order, kFactorParts, numeric_transpose, side_.c);
                        schedule_ = std::move(early.plan);
                        early_upper_ = early.upper;
                        seconds[1] = sw.seconds();
                      }});
    else
      symbolic();
    if (std::getenv("COLONFLAT_FLATTEN_DEBUG") && std::size_t(A.rows()) >= kThreadedFactorMinRows)
      std::fprintf(stderr, "flatten debug analysis: %ld unknowns, wall s: symbolic %.2f, schedule %.2f (side by side)\n",
                   long(A.rows()), seconds[0], seconds[1]);
    if (factor_ && std::equal(order->begin(), order->end(), static_cast<const int*>(factor_->Perm))) given_order_ = *order;
    else release_early();
  } else {
    factor_ = cholmod_analyze(&view, &common_);
  }
}

bool SpdSolver::factorize(const SpMat& A) {
  tree_.reset();
  group_solves_ = 0;
  if (factor_) {
    cholmod_sparse view = view_lower(A);
    ThreadedUse use;
    const int threaded = factorize_on_threads(&view, factor_, common_, EarlyRows{std::move(schedule_), early_upper_}, use);
    release_early();  // made for this factorisation only
    early_schedule_ = use.early_schedule;
    early_transpose_ = use.early_transpose;
    rest_blocks_ = use.rest_blocks;
    threaded_transposes_ += use.transposes;
    if (threaded < 0) cholmod_factorize(&view, factor_, &common_);
    cholmod_ok_ = threaded != 0 && common_.status >= CHOLMOD_OK && factor_->minor == factor_->n;
    if (cholmod_ok_) return true;
  }
  return fall_back(A);
}

std::size_t SpdSolver::factor_entries() const { return factor_ ? std::size_t(factor_->nzmax) : 0; }

int SpdSolver::dense_root_columns() const {
  if (!factor_ || !factor_->ColCount) return 0;
  const int* count = static_cast<const int*>(factor_->ColCount);
  const long n = long(factor_->n);
  long j = n - 1;
  while (j >= 0 && count[j] >= n - j) --j;
  return int(n - 1 - j);
}

Eigen::MatrixXd SpdSolver::solve(const Eigen::MatrixXd& b) const {
  if (!cholmod_ok_) return fallback_->solve(b);
  // kColumnsPerSolveCall columns per CHOLMOD call (the last group fewer), the groups on the worker
  // threads for a large factor: each column's arithmetic is that of its one-column call whoever
  // solves it and whatever its group, so the result depends neither on the thread count nor on the
  // threshold.
  Eigen::MatrixXd x(b.rows(), b.cols());
  const Eigen::Index width = kColumnsPerSolveCall;
  auto solve_group = [&](Eigen::Index first, cholmod_common& common) {
    const Eigen::Index k = std::min(width, b.cols() - first);
    const Eigen::MatrixXd group = b.middleCols(first, k);
    cholmod_dense rhs = view_dense(group);
    cholmod_dense* xg = cholmod_solve(CHOLMOD_A, factor_, &rhs, &common);
    if (!xg) throw Error("sparse solve failed (CHOLMOD status " + std::to_string(common.status) + ")");
    x.middleCols(first, k) = take_dense(xg, common);
  };
  solve_calls_ += int((b.cols() + width - 1) / width);
  if (factor_entries() >= kThreadedSolveMinEntries && b.cols() <= width && thread_count() > 1 &&
      ++group_solves_ >= kTreeSolveFrom)
    if (const std::shared_ptr<const TreeSolve> plan = tree_plan()) return tree_solve(*plan, b);
  if (factor_entries() < kThreadedSolveMinEntries || b.cols() <= width) {
    ThreadCommon common;
    for (Eigen::Index c = 0; c < b.cols(); c += width) solve_group(c, common.c);
    return x;
  }
  std::vector<std::function<void()>> groups;
  for (Eigen::Index c = 0; c < b.cols(); c += width)
    groups.push_back([&, c] {
      ThreadCommon common;
      solve_group(c, common.c);
    });
  parallel_tasks(groups);
  return x;
}

// The plan of the factor as it is now, made once (null when TreeSolve cannot take it).
std::shared_ptr<const TreeSolve> SpdSolver::tree_plan() const {
  std::lock_guard<std::mutex> lock(tree_mutex_);
  if (!tree_) {
    const Stopwatch sw;
    auto plan = std::make_shared<const TreeSolve>(factor_);
    if (std::getenv("COLONFLAT_FLATTEN_DEBUG"))
      std::fprintf(stderr, "flatten debug tree solve: %zu unknowns, entries parts %zu / %zu, rest %zu, kept %zu, plan %.3f s\n",
                   std::size_t(factor_->n), plan->part_entries(0), plan->part_entries(1), plan->rest_entries(),
                   plan->kept_terms(), sw.seconds());
    tree_ = std::move(plan);
  }
  return tree_->usable() ? tree_ : nullptr;
}

// x = A^-1 b by the plan: b permuted into L's order in row form, solved, permuted back (as
// cholmod_solve does: copies only, here on the worker threads).
Eigen::MatrixXd SpdSolver::tree_solve(const TreeSolve& plan, const Eigen::MatrixXd& b) const {
  const std::size_t n = factor_->n, k = std::size_t(b.cols());
  const int* perm = static_cast<const int*>(factor_->Perm);
  std::vector<double> y(n * k);
  parallel_for(n, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i)
      for (std::size_t c = 0; c < k; ++c) y[i * k + c] = b(perm[i], Eigen::Index(c));
  });
  plan.solve(y.data(), int(k));
  Eigen::MatrixXd x(b.rows(), b.cols());
  parallel_for(n, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i)
      for (std::size_t c = 0; c < k; ++c) x(perm[i], Eigen::Index(c)) = y[i * k + c];
  });
  ++tree_solves_;
  return x;
}

// P, L, (the rows past the leading block zeroed), D, L^T, P^T: one step at a time.
Eigen::MatrixXd SpdSolver::cholmod_leading(const Eigen::MatrixXd& b, int leading) const {
  ThreadCommon common;
  cholmod_dense rhs = view_dense(b);
  cholmod_dense* y = cholmod_solve(CHOLMOD_P, factor_, &rhs, &common.c);
  for (int system : {CHOLMOD_L, CHOLMOD_D, CHOLMOD_Lt, CHOLMOD_Pt}) {
    if (!y) break;
    if (system == CHOLMOD_D)
      for (std::size_t c = 0; c < y->ncol; ++c)
        std::fill(static_cast<double*>(y->x) + c * y->d + leading, static_cast<double*>(y->x) + c * y->d + y->nrow, 0.0);
    cholmod_dense* next = cholmod_solve(system, factor_, y, &common.c);
    cholmod_free_dense(&y, &common.c);
    y = next;
  }
  if (!y) throw Error("sparse solve failed (CHOLMOD status " + std::to_string(common.c.status) + ")");
  return take_dense(y, common.c);
}

bool SpdSolver::modify(const SpMat& C, bool update) {
  if (!cholmod_ok_ || C.cols() == 0) return cholmod_ok_;
  tree_.reset();  // the update may change L's pattern
  group_solves_ = 0;
  const int* perm = static_cast<const int*>(factor_->Perm);
  std::vector<int> place(factor_->n);  // CHOLMOD wants C's rows in the factor's order
  for (std::size_t k = 0; k < factor_->n; ++k) place[perm[k]] = int(k);
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(std::size_t(C.nonZeros()));
  for (int j = 0; j < C.outerSize(); ++j)
    for (SpMat::InnerIterator it(C, j); it; ++it) entries.emplace_back(place[it.row()], j, it.value());
  SpMat permuted(C.rows(), C.cols());
  permuted.setFromTriplets(entries.begin(), entries.end());  // compressed, rows sorted
  cholmod_sparse view = view_columns(std::size_t(C.rows()), std::size_t(C.cols()), permuted.outerIndexPtr(),
                                     permuted.innerIndexPtr(), permuted.valuePtr(), 0);  // unsymmetric: C itself
  cholmod_updown(update ? 1 : 0, &view, factor_, &common_);
  cholmod_ok_ = common_.status == CHOLMOD_OK && factor_->minor == factor_->n;
  return cholmod_ok_;
}

double SpdSolver::factor_flops() const { return factor_ ? common_.fl : 0.0; }

double SpdSolver::modify_flops(const std::vector<const SpMat*>& terms, double limit) const {
  if (!cholmod_ok_ || factor_->is_super) return 0.0;
  const std::size_t n = factor_->n;
  const int* Lp = static_cast<const int*>(factor_->p);
  const int* Li = static_cast<const int*>(factor_->i);
  const int* Lnz = static_cast<const int*>(factor_->nz);
  std::vector<int> parent(n, -1), place(n);  // elimination tree: the first row below the diagonal
  for (std::size_t j = 0; j < n; ++j) {
    int first = -1;
    for (int k = Lp[j]; k < Lp[j] + Lnz[j]; ++k)
      if (Li[k] > int(j) && (first < 0 || Li[k] < first)) first = Li[k];
    parent[j] = first;
  }
  const int* perm = static_cast<const int*>(factor_->Perm);
  for (std::size_t k = 0; k < n; ++k) place[perm[k]] = int(k);
  double flops = 0;
  for (const SpMat* C : terms)
    for (int c = 0; c < C->outerSize() && flops <= limit; ++c) {
      int j = int(n);
      for (SpMat::InnerIterator it(*C, c); it; ++it) j = std::min(j, place[it.row()]);
      for (; j >= 0 && j < int(n); j = parent[j]) flops += 4.0 * Lnz[j];
    }
  return flops;
}

std::vector<int> SpdSolver::order() const {
  if (!factor_ || !factor_->Perm) return {};
  const int* perm = static_cast<const int*>(factor_->Perm);
  return std::vector<int>(perm, perm + factor_->n);
}

#else  // Eigen only: the order is Eigen's AMD unless one is given

std::vector<int> SpdSolver::fill_reducing_order(const SpMat& A) { return Fallback::eigen_amd(A); }

std::vector<int> SpdSolver::nested_dissection_order(const SpMat& A) { return Fallback::eigen_amd(A); }

std::vector<int> SpdSolver::one_call_dissection_order(const SpMat&) { return {}; }

double SpdSolver::order_flops(const SpMat&, const std::vector<int>&) { return 0.0; }

int SpdSolver::dense_root_columns() const { return 0; }

void SpdSolver::release() {}

bool SpdSolver::compute(const SpMat& A, const std::vector<int>* order) {
  analyze(A, order);
  return factorize(A);
}

void SpdSolver::analyze(const SpMat& A, const std::vector<int>* order) {
  fallback_.reset();
  given_order_.clear();
  if (order && order->size() == std::size_t(A.rows())) given_order_ = *order;
}

bool SpdSolver::factorize(const SpMat& A) { return fall_back(A); }

Eigen::MatrixXd SpdSolver::solve(const Eigen::MatrixXd& b) const { return fallback_->solve(b); }

bool SpdSolver::modify(const SpMat&, bool) { return false; }

double SpdSolver::factor_flops() const { return 0.0; }

std::size_t SpdSolver::factor_entries() const { return 0; }

double SpdSolver::modify_flops(const std::vector<const SpMat*>&, double) const { return 0.0; }

std::vector<int> SpdSolver::order() const { return {}; }

#endif

}  // namespace cf::flat_detail
