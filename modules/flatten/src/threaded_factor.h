#pragma once
// The threaded numeric factorisation of SpdSolver (CHOLMOD's simplicial LDL^T with its rows split
// over the worker threads along the elimination tree, factor_schedule.h), and the per-thread
// cholmod_common that it and the solves use. CHOLMOD builds only.
#ifdef COLONFLAT_HAVE_CHOLMOD
#include <cholmod.h>

#include <cstddef>
#include <vector>

#include "factor_schedule.h"

namespace cf::flat_detail {

// A cholmod_common of the calling thread's own (CHOLMOD's statistics and workspace live there):
// solves with a finished factor, and rows of one factorisation, may then run on several threads.
struct ThreadCommon {
  cholmod_common c{};
  ThreadCommon() {
    cholmod_start(&c);
    c.print = 0;
  }
  ~ThreadCommon() { cholmod_finish(&c); }
  ThreadCommon(const ThreadCommon&) = delete;
  ThreadCommon& operator=(const ThreadCommon&) = delete;
};

// A factorisation from this many unknowns on has its rows split over the worker threads (below it
// one factorisation takes a few tens of milliseconds).
constexpr std::size_t kThreadedFactorMinRows = 20000;

// The row schedule (factor_schedule.h, schedule_phases with row_work) of the pattern of
// triu(A(p,p)) for `lower` = A's lower triangle (stype -1) and p = `order` (a permutation of
// 0..n-1), for `parts` threads, with a cholmod_common of the calling thread's own; empty when the
// transpose fails. What the analysis of a given order leaves for factorize_on_threads, computed
// beside it.
std::vector<RowSchedule> pattern_schedule(cholmod_sparse* lower, const std::vector<int>& order, int parts);

// cholmod_factorize of the simplicial LDL^T `L` (symbolic, CHOLMOD_PATTERN, from the analysis of
// `lower`'s pattern) with its rows split over thread_count() worker threads; `ready` (may be empty):
// the schedule of this factor's pattern for thread_count() parts, computed beforehand
// (pattern_schedule); `early` is set when it was used. Post: L numeric and bit for bit
// cholmod_factorize's. Returns -1 (nothing done: one thread, fewer than kThreadedFactorMinRows
// rows, supernodal or already numeric L), 0 when the factorisation failed, 1 when it succeeded.
int factorize_on_threads(cholmod_sparse* lower, cholmod_factor* L, cholmod_common& common, std::vector<RowSchedule> ready,
                         bool& early);

}  // namespace cf::flat_detail
#endif
