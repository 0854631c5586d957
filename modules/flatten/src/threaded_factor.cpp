// The threaded numeric factorisation of SpdSolver (see threaded_factor.h).
#include "threaded_factor.h"

#ifdef COLONFLAT_HAVE_CHOLMOD
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <functional>

#include "colonflat/core/run_stats.h"
#include "colonflat/core/threads.h"
#include "factor_memory.h"
#include "rest_blocks.h"

namespace cf::flat_detail {

namespace {

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
FactorPlan factor_schedule(cholmod_sparse* upper, int parts) {
  const int n = int(upper->ncol);
  const int* colptr = static_cast<const int*>(upper->p);
  const int* rowind = static_cast<const int*>(upper->i);
  FactorPlan plan;
  plan.parent = elimination_tree(n, colptr, rowind);
  plan.phases = schedule_phases(plan.parent, row_work(n, colptr, rowind, plan.parent), parts);
  return plan;
}

// COLONFLAT_FLATTEN_DEBUG: the last rest's estimated work split by the columns its updates read
// (split_rest_work, of `upper` = triu(A(p,p)) with elimination tree `parent`).
RestWork debug_rest_work(const cholmod_sparse* upper, const std::vector<int>& parent, const std::vector<int>& rest) {
  const int n = int(upper->ncol);
  return split_rest_work(n, static_cast<const int*>(upper->p), static_cast<const int*>(upper->i), parent, rest);
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

// Whether the last phase's rest is computed in blocks (threaded_factor.h: kRestBlocksMinRows,
// kRestBlocksMinWork; the schedule is of kFactorParts parts whatever the thread count).
bool rest_in_blocks(const RowSchedule& last) {
  return last.rest.size() >= kRestBlocksMinRows && last.rest_work >= kRestBlocksMinWork;
}

// The rows above the last phase's parts of `plan`: in blocks (`blocks`) or by cholmod_rowfac on the
// calling thread; `rest_cpu`: the calling thread's CPU seconds, `wall` (blocks): the blocks' stretches.
bool factor_rest(cholmod_sparse* upper, const FactorPlan& plan, bool blocks, cholmod_factor* L, cholmod_common& common,
                 double& rest_cpu, RestBlockWall& wall) {
  const std::vector<int>& rest = plan.phases.back().rest;
  if (!blocks) return rowfac_rows(upper, rest, L, common, &rest_cpu) && L->minor == L->n;
  const double start = thread_cpu_seconds();
  const bool ok = factor_rest_in_blocks(upper, plan.parent, rest, L, &wall);
  rest_cpu = thread_cpu_seconds() - start;
  return ok;
}

// COLONFLAT_FLATTEN_DEBUG: the rest's blocks.
void print_blocks_debug(const RestBlockWall& w) {
  std::fprintf(stderr, "flatten debug factor rest in blocks: %zu rows, %zu entries in the parts' columns; wall s: row "
               "solves %.2f, copy %.2f, Schur complement %.2f, dense root %.2f\n", w.rows, w.entries_from_parts,
               w.solves, w.copy, w.schur, w.root);
}

}  // namespace

EarlyRows early_rows(cholmod_sparse* lower, const std::vector<int>& order, int parts, bool numeric,
                     cholmod_common& common) {
  EarlyRows out;
  // values 2: as cholmod_factorize transposes (the conjugate; for real values the same copy)
  cholmod_sparse* upper = cholmod_ptranspose(lower, numeric ? 2 : 0, const_cast<int*>(order.data()), nullptr, 0, &common);
  if (!upper) return out;
  out.plan = factor_schedule(upper, parts);
  if (numeric) out.upper = upper;
  else cholmod_free_sparse(&upper, &common);
  return out;
}

// cholmod_factorize of a simplicial LDL^T, as CHOLMOD does it (upper = triu(A(p,p)) by
// cholmod_ptranspose, L made numeric with exactly its column counts, cholmod_rowfac over the rows),
// with the rows split over the worker threads (factor_schedule.h): in each phase, parts of whole
// subtrees side by side, then the rows above the last phase's, in blocks when large enough
// (rest_blocks.h). Row k reads only the columns of its subtree and each column gets its entries in
// increasing row order, so outside the blocks the factor is bit for bit cholmod_factorize's for any
// thread count; the blocks' bits do not depend on it either (see threaded_factor.h).
int factorize_on_threads(cholmod_sparse* lower, cholmod_factor* L, cholmod_common& common, EarlyRows ready,
                         ThreadedUse& use) {
  if (L->n < kThreadedFactorMinRows || L->is_super || L->xtype != CHOLMOD_PATTERN) return -1;
  const int threads = thread_count();  // (one thread: the parts one after the other)
  const Stopwatch sw;
  Stopwatch lap;
  FactorWall wall;
  cholmod_sparse* made = nullptr;  // the transpose made here, when none was ready
  if (!ready.upper)
    made = cholmod_ptranspose(lower, 2, L->ordering == CHOLMOD_NATURAL ? nullptr : static_cast<int*>(L->Perm), nullptr, 0, &common);
  cholmod_sparse* upper = ready.upper ? ready.upper : made;
  if (!upper) return -1;
  use.early_transpose = ready.upper != nullptr;
  use.transposes = made ? 1 : 0;
  bool& early = use.early_schedule;
  early = ready.plan.phases.size() > 0 && ready.plan.phases.front().parts.size() == std::size_t(kFactorParts);
  FactorPlan plan = early ? std::move(ready.plan) : factor_schedule(upper, kFactorParts);
  std::vector<RowSchedule>& phases = plan.phases;
  wall.transpose = lap.lap();
  L->is_ll = common.final_ll ? 1 : 0;
  const std::size_t grow2 = common.grow2;
  if (common.final_pack) common.grow2 = 0;  // exactly the space required, as cholmod_factorize asks
  bool ok = cholmod_change_factor(CHOLMOD_REAL, L->is_ll, 0, 0, 1, L, &common);
  common.grow2 = grow2;
  use.rest_blocks = rest_in_blocks(phases.back()) && !L->is_ll;
  if (ok && !columns_have_room(L)) {  // (not expected) every row here, in order
    early = use.rest_blocks = false;
    phases.assign(1, RowSchedule{});
    phases[0].rest.resize(L->n);
    for (std::size_t k = 0; k < L->n; ++k) phases[0].rest[k] = int(k);
  }
  wall.numeric = lap.lap();
  std::vector<double> cpu(std::size_t(kFactorParts), 0.0);  // per part (summed over phases), then each phase's longest
  for (const RowSchedule& phase : phases) ok = ok && factor_parts(upper, phase, L, cpu, wall.wait);
  wall.parts = lap.lap();
  double rest_cpu = 0;
  RestBlockWall blocks;
  ok = ok && factor_rest(upper, plan, use.rest_blocks, L, common, rest_cpu, blocks);
  wall.rest = lap.lap();
  const bool debug = std::getenv("COLONFLAT_FLATTEN_DEBUG") != nullptr;
  const RestWork rest_split = debug ? debug_rest_work(upper, plan.parent, phases.back().rest) : RestWork{};  // (before `made` is freed)
  const double walk = lap.lap();  // (not part of the factorisation's time)
  if (made) cholmod_free_sparse(&made, &common);
  wall.free = lap.lap();
  if (debug) {
    print_factor_debug(kFactorParts, threads, L->n, phases, cpu, rest_cpu, sw.seconds() - walk, early, wall, rest_split);
    if (use.rest_blocks) print_blocks_debug(blocks);
    const BlockCache::Stats s = cholmod_block_cache().stats();
    std::fprintf(stderr, "flatten debug factor memory: large blocks so far %zu reused, %zu fresh; %zu kept now; numeric "
                 "transpose %s\n", s.reused, s.fresh, s.kept, use.early_transpose ? "made beside the analysis" : "made here");
  }
  return ok ? 1 : 0;
}

}  // namespace cf::flat_detail
#endif
