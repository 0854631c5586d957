#pragma once
// Rows of a sparse LDL^T factor split over threads. CHOLMOD's simplicial factorisation is
// up-looking: row k of L is computed from A's column k and the columns of L of k's descendants in
// the elimination tree, and writes only those columns and its own. Rows of disjoint subtrees are
// therefore independent: several threads may compute them at once on one factor, and the rows
// above them (their ancestors) follow. Every row's arithmetic is the same whoever computes it and
// every column still receives its entries in increasing row order, so the factor is bit for bit
// the factor of the sequential factorisation, for any split (see spd_solver.cpp).
#include <cstddef>
#include <vector>

namespace cf::flat_detail {

struct RowSchedule {
  // Rows computed side by side: each part a union of whole elimination subtrees, rows ascending.
  std::vector<std::vector<int>> parts;
  // The rows computed after every part (ancestors of the parts' subtrees), ascending.
  std::vector<int> rest;
  // Estimated work (sum of the `work` given) of the largest part, of `rest` and of all rows.
  double largest_part = 0, rest_work = 0, total_work = 0;
};

// What a threaded factorisation follows: the row schedule's phases and the elimination tree they
// were made from (the rest's blocks walk the tree again: rest_blocks.h).
struct FactorPlan {
  std::vector<RowSchedule> phases;  // schedule_phases() (empty: none)
  std::vector<int> parent;          // elimination_tree() of triu(A(p,p)), n entries
  void clear() { phases.clear(), parent.clear(); }
};

// Elimination tree of a symmetric matrix given by its upper triangle in compressed columns (column
// k: rows <= k, colptr[n + 1], rowind[colptr[n]]): parent[k] > k, or -1 for a root (Liu's algorithm
// with path compression).
std::vector<int> elimination_tree(int n, const int* colptr, const int* rowind);

// The cost of computing each row of L by the up-looking kernel (cholmod_rowfac), for the upper
// triangle given as above and its elimination tree `parent`: row k's pattern is the union of the
// tree paths from the rows i < k of column k up to k; for each column j on it the kernel updates
// with the entries column j holds so far (rows j < i < k) and appends L(k, j). work[k] = 1 + the sum
// over j of (1 + those entries): multiply-adds plus one per entry written. Summed over all rows it is
// sum_j c_j (c_j + 1) / 2 + n (c_j: entries below the diagonal of column j), but each column's work is
// counted at the later rows that do it, not at the column's own row. O(entries of L) time, O(n) memory.
std::vector<double> row_work(int n, const int* colptr, const int* rowind, const std::vector<int>& parent);

// The estimated work (row_work) of the rows `rest` (closed under ancestors: the rows above the
// parts) split by the column each update reads: `from_parts`, the updates with the columns of rows
// outside `rest` (finished before the rest starts: row k's entries in the columns of one part's
// subtree depend only on that subtree and on A's column k), and `own`, the updates with the rest's
// own columns plus one per diagonal (a chain at a dense root). from_parts + own = the rest's work.
// What a finer split of the rest could at most run side by side (COLONFLAT_FLATTEN_DEBUG).
struct RestWork {
  double from_parts = 0, own = 0;
};
RestWork split_rest_work(int n, const int* colptr, const int* rowind, const std::vector<int>& parent,
                         const std::vector<int>& rest);

// Splits the rows of the elimination tree `parent` into `parts` unions of whole subtrees and the
// rest above them, so that the largest part plus the rest (the time with `parts` threads) is as
// small as this search finds: starting from the roots, the heaviest subtree is repeatedly replaced
// by its children (its own row goes to the rest), the subtrees dealt to the parts largest first,
// each to the lightest part; the best split seen is kept. `work[k]` >= 0: the estimated cost of
// row k (the caller: row_work). Deterministic (ties by row index).
RowSchedule schedule_rows(const std::vector<int>& parent, const std::vector<double>& work, int parts);

// schedule_rows, then its rest split again the same way (the rest is closed under ancestors: its
// rows form a forest whose subtrees only read finished parts and their own rows), while a split
// saves more than kPhaseMinGain of the rest's estimated work; at most kMaxPhases phases. Phase i's
// parts run side by side after phase i - 1; only the last phase's rest is left (the others' rest
// is empty). Rows are global, ascending in every part and rest.
std::vector<RowSchedule> schedule_phases(const std::vector<int>& parent, const std::vector<double>& work, int parts);
constexpr double kPhaseMinGain = 0.05;
constexpr int kMaxPhases = 8;

// CPU seconds of the calling thread (COLONFLAT_FLATTEN_DEBUG: the threaded factorisation's parts).
double thread_cpu_seconds();
// Seconds the calling thread has waited on a run queue for a core (Linux /proc/thread-self/schedstat;
// 0 where unavailable): a part's wall beyond its CPU on a shared machine.
double thread_wait_seconds();
// Wall seconds of the serial and threaded stretches of one threaded factorisation (debug line).
struct FactorWall {
  double transpose = 0;  // the numeric transpose triu(A(p,p)) (cholmod_ptranspose)
  double numeric = 0;    // L made numeric (cholmod_change_factor: L's arrays allocated, set to the identity)
  double parts = 0;      // the phases' parts side by side (each phase as long as its longest part)
  double rest = 0;       // the rows above the last phase's parts, on the calling thread
  double free = 0;       // the transpose freed
  std::vector<double> wait;  // per part (summed over phases): seconds its thread waited for a core
};
// COLONFLAT_FLATTEN_DEBUG: the schedule's estimate against the CPU seconds measured (`cpu`: per part
// summed over the phases, then each phase's longest; `early`: the schedule was computed beside the
// symbolic analysis), the wall of each stretch and the last rest's work split (`rest`: split_rest_work).
void print_factor_debug(int parts, int threads, std::size_t n, const std::vector<RowSchedule>& phases, const std::vector<double>& cpu,
                        double rest_cpu, double seconds, bool early, const FactorWall& wall, const RestWork& rest);

}  // namespace cf::flat_detail
