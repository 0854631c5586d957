#pragma once
// The solve A x = b with a simplicial LDL^T factor (CHOLMOD's) on two threads, to the bit what
// cholmod_solve(CHOLMOD_A) gives on one: its kernels ldl_lsolve (L y = b, unit diagonal, column
// oriented: each column's value scattered into the rows below it) then ldl_dltsolve (D L^T x = y,
// each column's value gathered from the rows below it), replayed with the same chains of 1-3
// columns (CHOLMOD's "supernodes" of consecutive columns with nested patterns) and the same
// expressions, so every entry of x gets the same operations in the same order.
//
// Split: the columns are dealt into kParts parts of whole elimination subtrees (schedule_rows, work
// = the column's entries) and the rest above them (closed under ancestors). A column of one part
// only reaches rows of its own part or of the rest, and a row of a part only receives values of its
// own part's columns (its descendants). So:
// - L y = b: the parts side by side; a part's column updates its own rows at once (in column order:
//   CHOLMOD's order for those rows), and keeps each term for a rest row in its own buffer. Then on one
//   thread the rest rows get every kept term and the rest's chains in ascending column order (the
//   merged order the serial kernel gives them), runs of the two parts' buffers taken in turn.
// - D L^T x = y: the rest's chains first (descending; they read only rest rows), then the parts side
//   by side (their columns read their own rows and the rest's, all final).
// A chain with columns of a part and of the rest (a part's top column and its parent) is the rest's.
// The threads only change who computes a value, never its operations: x is the same bits for any
// thread count (on one the parts run one after the other) and equals CHOLMOD's (tested).
// CHOLMOD builds only.
#ifdef COLONFLAT_HAVE_CHOLMOD
#include <cholmod.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace cf::flat_detail {

class TreeSolve {
 public:
  static constexpr int kParts = 2;
  // Right-hand sides solved at once (CHOLMOD's kernels for 1-3 columns compute each column with the
  // one-column operations; the solve reads L once for all of them).
  static constexpr int kMaxColumns = 3;
  // The plan of `L` (simplicial, numeric, LDL^T, real; read, not owned: L must outlive this and not
  // change). usable() is false for any other factor.
  explicit TreeSolve(const cholmod_factor* L);
  bool usable() const { return L_ != nullptr; }
  // In place: Y (n x k in row form, Y[i * k + c]; rows in the factor's order, 1 <= k <= kMaxColumns)
  // := (L D L^T)^-1 Y, the parts on up to thread_count() threads. Pre: usable().
  void solve(double* Y, int k) const;
  // Entries of L in the columns of each part and of the rest, and the terms the parts keep for the
  // rest's rows (what the one-thread stretches read: rest + kept; COLONFLAT_FLATTEN_DEBUG).
  std::size_t part_entries(int part) const { return part_entries_[part]; }
  std::size_t rest_entries() const { return rest_entries_; }
  std::size_t kept_terms() const { return kept_[0] + kept_[1]; }

 private:
  // Columns first .. first + width - 1 (forward) or first - width + 1 .. first (backward); forward, a
  // part's: its first `split` rows below the chain are its own, the others the rest's.
  struct Chain {
    int first;
    int width;
    int split;
  };
  // A run of the rest's one-thread forward stretch: the next `count` chains of part `source` (their
  // kept terms) or of the rest (source kParts: solved), in ascending column order.
  struct Run {
    int source;
    std::size_t count;
  };
  void plan_chains(const std::vector<std::uint8_t>& owner, const std::vector<int>& top);
  template <int K>
  void forward_part(int part, double* Y, double* kept) const;
  template <int K>
  void forward_rest(double* Y, const double* kept0, const double* kept1) const;
  template <int K>
  void backward(const std::vector<Chain>& chains, double* Y) const;
  template <int K>
  void solve_k(double* Y) const;

  const cholmod_factor* L_ = nullptr;
  std::vector<std::uint8_t> owner_;  // per column: its part, or kParts for the rest
  std::vector<Chain> forward_[kParts + 1], backward_[kParts + 1];  // per part, then the rest's
  std::size_t kept_[kParts] = {0, 0};  // each part's kept terms
  std::vector<Run> runs_;
  std::size_t part_entries_[kParts] = {0, 0}, rest_entries_ = 0;
};

}  // namespace cf::flat_detail
#endif
