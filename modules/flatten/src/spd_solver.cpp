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

// A cholmod_common of the calling thread's own (CHOLMOD's statistics and workspace live there):
// solves with a finished factor, and rows of one factorisation, may then run on several threads.
struct ThreadCommon {
  cholmod_common c{};
  ThreadCommon() {
    cholmod_start(&c);
    c.print = 0;
  }
  ~ThreadCommon() { cholmod_finish(&c); }
};

// A factorisation from this many unknowns on has its rows split over the worker threads (below it
// one factorisation takes a few tens of milliseconds).
constexpr std::size_t kThreadedFactorMinRows = 20000;

// Whether every column of the numeric factor L can hold its column count (then cholmod_rowfac never
// reallocates L, which would move the arrays other threads write).
bool columns_have_room(const cholmod_factor* L) {
  const int* Lp = static_cast<const int*>(L->p);
  const int* next = static_cast<const int*>(L->next);
  const int* count = static_cast<const int*>(L->ColCount);
  for (std::size_t j = 0; j < L->n; ++j)
    if (Lp[next[j]] - Lp[j] < count[j]) return false;
  return true;
}

// cholmod_rowfac over `rows` (ascending), one call per run of consecutive rows; `cpu` (optional):
// the thread's CPU seconds it took.
bool rowfac_rows(cholmod_sparse* upper, const std::vector<int>& rows, cholmod_factor* L, cholmod_common& common,
                 double* cpu = nullptr) {
  const double start = cpu ? thread_cpu_seconds() : 0.0;
  double beta[2] = {0.0, 0.0};
  bool ok = true;
  for (std::size_t i = 0; i < rows.size() && ok;) {
    std::size_t j = i + 1;
    while (j < rows.size() && rows[j] == rows[j - 1] + 1) ++j;
    ok = cholmod_rowfac(upper, nullptr, beta, std::size_t(rows[i]), std::size_t(rows[j - 1]) + 1, L, &common) &&
         common.status >= CHOLMOD_OK;
    i = j;
  }
  if (cpu) *cpu = thread_cpu_seconds() - start;
  return ok;
}

// The rows of the factor split along the elimination tree of `upper` (= triu(A(p,p))) in phases,
// each row's work estimated as the up-looking kernel's cost of it (row_work): counted at the row
// that does it, so the rows above the parts (few, but each updating with long columns) weigh what
// they cost.
std::vector<RowSchedule> factor_schedule(cholmod_sparse* upper, int parts) {
  const int n = int(upper->ncol);
  const int* colptr = static_cast<const int*>(upper->p);
  const int* rowind = static_cast<const int*>(upper->i);
  const std::vector<int> parent = elimination_tree(n, colptr, rowind);
  return schedule_phases(parent, row_work(n, colptr, rowind, parent), parts);
}

// factor_schedule() of the pattern of triu(A(p,p)), p = `order`, with a cholmod_common of the
// calling thread's own (empty when the transpose fails): what the analysis of a given order leaves
// for factorize_on_threads, computed beside it.
std::vector<RowSchedule> pattern_schedule(cholmod_sparse* lower, const std::vector<int>& order, int parts) {
  ThreadCommon tc;
  cholmod_sparse* upper = cholmod_ptranspose(lower, 0, const_cast<int*>(order.data()), nullptr, 0, &tc.c);
  if (!upper) return {};
  std::vector<RowSchedule> phases = factor_schedule(upper, parts);
  cholmod_free_sparse(&upper, &tc.c);
  return phases;
}

// One phase's parts side by side, each with its own cholmod_common; cpu[p] += part p's CPU seconds,
// wait[p] += the seconds its thread waited for a core.
bool factor_parts(cholmod_sparse* upper, const RowSchedule& phase, cholmod_factor* L, std::vector<double>& cpu,
                  std::vector<double>& wait) {
  std::vector<char> ok(phase.parts.size(), 0);
  std::vector<double> seconds(phase.parts.size(), 0.0);
  wait.resize(std::max(wait.size(), phase.parts.size()), 0.0);
  std::vector<std::function<void()>> tasks;
  for (std::size_t p = 0; p < phase.parts.size(); ++p)
    tasks.push_back([&, p] {
      const double waited = thread_wait_seconds();
      ThreadCommon tc;
      ok[p] = rowfac_rows(upper, phase.parts[p], L, tc.c, &seconds[p]);
      wait[p] += thread_wait_seconds() - waited;
    });
  parallel_tasks(tasks);
  cpu.resize(std::max(cpu.size(), seconds.size()), 0.0);
  for (std::size_t p = 0; p < seconds.size(); ++p) cpu[p] += seconds[p];
  cpu.push_back(seconds.empty() ? 0.0 : *std::max_element(seconds.begin(), seconds.end()));  // the phase's longest
  return std::count(ok.begin(), ok.end(), 1) == std::ptrdiff_t(ok.size());
}

// cholmod_factorize of a simplicial LDL^T, as CHOLMOD does it (upper = triu(A(p,p)) by
// cholmod_ptranspose, L made numeric with exactly its column counts, cholmod_rowfac over all
// rows), with the rows split over the worker threads (factor_schedule.h): in each phase, parts of
// whole subtrees side by side, then the rows above the last phase's. Row k reads only the columns
// of its subtree and each column gets its entries in increasing row order, so the factor is bit
// for bit cholmod_factorize's for any thread count. `ready` (may be empty): the schedule of this
// factor's pattern for thread_count() parts, computed beforehand (pattern_schedule); `early`: it
// was used. Returns -1
// (nothing done) when this does not apply, 0 when the factorisation failed, 1 when it succeeded.
int factorize_on_threads(cholmod_sparse* lower, cholmod_factor* L, cholmod_common& common,
                         std::vector<RowSchedule> ready, bool& early) {
  const int parts = thread_count();
  if (parts < 2 || L->n < kThreadedFactorMinRows || L->is_super || L->xtype != CHOLMOD_PATTERN) return -1;
  const Stopwatch sw;
  Stopwatch lap;
  FactorWall wall;
  cholmod_sparse* upper =
      cholmod_ptranspose(lower, 2, L->ordering == CHOLMOD_NATURAL ? nullptr : static_cast<int*>(L->Perm), nullptr, 0, &common);
  if (!upper) return -1;
  early = ready.size() > 0 && ready.front().parts.size() == std::size_t(parts);
  std::vector<RowSchedule> phases = early ? std::move(ready) : factor_schedule(upper, parts);
  wall.transpose = lap.lap();
  L->is_ll = common.final_ll ? 1 : 0;
  const std::size_t grow2 = common.grow2;
  if (common.final_pack) common.grow2 = 0;  // exactly the space required, as cholmod_factorize asks
  bool ok = cholmod_change_factor(CHOLMOD_REAL, L->is_ll, 0, 0, 1, L, &common);
  common.grow2 = grow2;
  if (ok && !columns_have_room(L)) {  // (not expected) every row here, in order
    early = false;
    phases.assign(1, RowSchedule{});
    phases[0].rest.resize(L->n);
    for (std::size_t k = 0; k < L->n; ++k) phases[0].rest[k] = int(k);
  }
  wall.numeric = lap.lap();
  std::vector<double> cpu(std::size_t(parts), 0.0);  // per part (summed over phases), then each phase's longest
  for (const RowSchedule& phase : phases) ok = ok && factor_parts(upper, phase, L, cpu, wall.wait);
  wall.parts = lap.lap();
  double rest_cpu = 0;
  ok = ok && rowfac_rows(upper, phases.back().rest, L, common, &rest_cpu) && L->minor == L->n;
  wall.rest = lap.lap();
  cholmod_free_sparse(&upper, &common);
  wall.free = lap.lap();
  if (std::getenv("COLONFLAT_FLATTEN_DEBUG")) {
    print_factor_debug(parts, L->n, phases, cpu, rest_cpu, sw.seconds(), early, wall);
    const BlockCache::Stats s = cholmod_block_cache().stats();
    std::fprintf(stderr, "flatten debug factor memory: large blocks so far %zu reused, %zu fresh; %zu kept now\n", s.reused,
                 s.fresh, s.kept);
  }
  return ok ? 1 : 0;
}

}  // namespace

std::vector<int> SpdSolver::fill_reducing_order(const SpMat& A) {
  std::vector<int> order = cholmod_order(A, false);
  return order.empty() ? Fallback::eigen_amd(A) : order;
}

std::vector<int> SpdSolver::one_call_dissection_order(const SpMat& A) { return cholmod_order(A, true); }

std::vector<int> SpdSolver::nested_dissection_order(const SpMat& A) {
  std::vector<int> order = metis_split_dissection_order(A);
  if (order.empty()) order = cholmod_order(A, true);
  return order.empty() ? fill_reducing_order(A) : order;
}

void SpdSolver::release() {
  schedule_.clear();
  early_schedule_ = false;
  if (factor_) cholmod_free_factor(&factor_, &common_);
  if (started_) cholmod_finish(&common_);
  started_ = false;
  cholmod_ok_ = false;
}

void SpdSolver::analyze(const SpMat& A, const std::vector<int>* order) {
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
    const int parts = thread_count();
    if (parts > 1 && std::size_t(A.rows()) >= kThreadedFactorMinRows)
      parallel_tasks({symbolic, [&] {
                        const Stopwatch sw;
                        schedule_ = pattern_schedule(&view, *order, parts);
                        seconds[1] = sw.seconds();
                      }});
    else
      symbolic();
    if (std::getenv("COLONFLAT_FLATTEN_DEBUG") && std::size_t(A.rows()) >= kThreadedFactorMinRows)
      std::fprintf(stderr, "flatten debug analysis: %ld unknowns, wall s: symbolic %.2f, schedule %.2f (side by side)\n",
                   long(A.rows()), seconds[0], seconds[1]);
    if (factor_ && std::equal(order->begin(), order->end(), static_cast<const int*>(factor_->Perm))) given_order_ = *order;
    else schedule_.clear();
  } else {
    factor_ = cholmod_analyze(&view, &common_);
  }
}

bool SpdSolver::factorize(const SpMat& A) {
  if (factor_) {
    cholmod_sparse view = view_lower(A);
    early_schedule_ = false;
    const int threaded = factorize_on_threads(&view, factor_, common_, std::move(schedule_), early_schedule_);
    schedule_.clear();
    if (threaded < 0) cholmod_factorize(&view, factor_, &common_);
    cholmod_ok_ = threaded != 0 && common_.status >= CHOLMOD_OK && factor_->minor == factor_->n;
    if (cholmod_ok_) return true;
  }
  return fall_back(A);
}

std::size_t SpdSolver::factor_entries() const { return factor_ ? std::size_t(factor_->nzmax) : 0; }

Eigen::MatrixXd SpdSolver::solve(const Eigen::MatrixXd& b) const {
  if (!cholmod_ok_) return fallback_->solve(b);
  // Column by column, on the worker threads for a large factor: each column's arithmetic is the
  // same whoever solves it (the same one-column call), so the result does not depend on the thread
  // count nor on the threshold.
  Eigen::MatrixXd x(b.rows(), b.cols());
  auto solve_column = [&](Eigen::Index c, cholmod_common& common) {
    const Eigen::MatrixXd column = b.col(c);
    cholmod_dense rhs = view_dense(column);
    cholmod_dense* xc = cholmod_solve(CHOLMOD_A, factor_, &rhs, &common);
    if (!xc) throw Error("sparse solve failed (CHOLMOD status " + std::to_string(common.status) + ")");
    x.col(c) = take_dense(xc, common);
  };
  if (factor_entries() < kThreadedSolveMinEntries) {
    ThreadCommon common;
    for (Eigen::Index c = 0; c < b.cols(); ++c) solve_column(c, common.c);
    return x;
  }
  std::vector<std::function<void()>> columns;
  for (Eigen::Index c = 0; c < b.cols(); ++c)
    columns.push_back([&, c] {
      ThreadCommon common;
      solve_column(c, common.c);
    });
  parallel_tasks(columns);
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
  const int* perm = static_cast<const int*>(factor_->Perm);
  std::vector<int> place(factor_->n);  // CHOLMOD wants C's rows in the factor's order
  for (std::size_t k = 0; k < factor_->n; ++k) place[perm[k]] = int(k);
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(std::size_t(C.nonZeros()));
  for (int j = 0; j < C.outerSize(); ++j)
    for (SpMat::InnerIterator it(C, j); it; ++it) entries.emplace_back(place[it.row()], j, it.value());
  SpMat permuted(C.rows(), C.cols());
  permuted.setFromTriplets(entries.begin(), entries.end());  // compressed, rows sorted
  cholmod_sparse view = view_lower(permuted);
  view.nrow = std::size_t(C.rows());
  view.ncol = std::size_t(C.cols());
  view.stype = 0;  // unsymmetric: C itself
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

void SpdSolver::release() {}

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
