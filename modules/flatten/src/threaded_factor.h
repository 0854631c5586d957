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
// The row schedule is made for this many parts whatever thread_count() is (one thread computes the
// parts one after the other), so the rest, hence the factor's bits when the rest is computed in
// blocks, is the same for every thread count. Two: the machines this runs on have two cores.
constexpr int kFactorParts = 2;
// The rest is computed in blocks (rest_blocks.h) when it has at least kRestBlocksMinRows rows and
// kRestBlocksMinWork of the schedule's estimated work (row_work units: about one multiply-add each;
// cholmod_rowfac does ~1.5e9 a second here); a smaller rest stays with cholmod_rowfac: at 9.1e7 (a
// 28 982-unknown band) the blocks took 0.06 CPU s / 0.16 s wall on 2 threads against rowfac's 0.07 /
// 0.16-0.19 (docs/flatten.md, session 26). A rule on the schedule of kFactorParts parts only: it does
// not depend on the thread count.
constexpr std::size_t kRestBlocksMinRows = 64;
constexpr double kRestBlocksMinWork = 1.2e8;

// What the analysis of a given order leaves for factorize_on_threads, computed beside it.
struct EarlyRows {
  FactorPlan plan;                    // for the parts it was made for (empty phases: none)
  cholmod_sparse* upper = nullptr;    // numeric triu(A(p,p)) (not owned here; null: none)
};

// The row schedule (factor_schedule.h, schedule_phases with row_work) of triu(A(p,p)) for `lower`
// = A's lower triangle (stype -1) and p = `order` (a permutation of 0..n-1), for `parts` threads.
// `numeric`: the transpose is made with A's values and returned in `upper` (allocated with
// `common`, the caller frees it with the same one), else of the pattern only and freed here.
// `common`: the calling thread's own. Empty plan and null upper when the transpose fails.
EarlyRows early_rows(cholmod_sparse* lower, const std::vector<int>& order, int parts, bool numeric,
                     cholmod_common& common);

// How a threaded factorisation went: whether it took the early schedule, the early transpose, and
// how many numeric transposes it made itself (0 or 1), and whether its rest was computed in blocks.
struct ThreadedUse {
  bool early_schedule = false, early_transpose = false, rest_blocks = false;
  int transposes = 0;
};

// The numeric factorisation of the simplicial LDL^T `L` (symbolic, CHOLMOD_PATTERN, from the
// analysis of `lower`'s pattern) with its rows split into kFactorParts parts by the row schedule,
// the parts on up to thread_count() worker threads; the rest (the rows above the parts) in blocks
// (rest_blocks.h) when it is large enough (kRestBlocksMinRows, kRestBlocksMinWork), else by
// cholmod_rowfac. `ready` (may be empty): early_rows() of this factor's pattern for kFactorParts
// parts, computed beforehand; its `upper`, when given, must be the numeric triu of this `lower` in
// L's order (it is read, not freed). Post: L numeric, the same bits for every thread count; bit for
// bit cholmod_factorize's when the rest is not in blocks (`use.rest_blocks` false), its rest's
// entries equal to rounding otherwise. Returns -1 (nothing done: fewer than kThreadedFactorMinRows
// rows, supernodal or already numeric L), 0 when the factorisation failed, 1 when it succeeded.
int factorize_on_threads(cholmod_sparse* lower, cholmod_factor* L, cholmod_common& common, EarlyRows ready,
                         ThreadedUse& use);

}  // namespace cf::flat_detail
#endif
