// The simplicial LDL^T solve split along the elimination tree over two threads, bit for bit
// CHOLMOD's (see tree_solve.h).
#include "tree_solve.h"

#ifdef COLONFLAT_HAVE_CHOLMOD
#include <algorithm>

#include "colonflat/core/threads.h"
#include "factor_schedule.h"

namespace cf::flat_detail {

namespace {

// The arrays of a simplicial factor (column j: entries p[j] .. p[j] + nz[j], its diagonal first).
struct Lview {
  const int *p, *i, *nz;
  const double* x;
  int n;
};

Lview view_of(const cholmod_factor* L) {
  return {static_cast<const int*>(L->p), static_cast<const int*>(L->i), static_cast<const int*>(L->nz),
          static_cast<const double*>(L->x), int(L->n)};
}

// The columns ldl_lsolve solves at once from column j (CHOLMOD's chain test, as written there).
int forward_width(const Lview& L, int j) {
  const int p = L.p[j], lnz = L.nz[j];
  if (lnz < 4 || lnz != L.nz[j + 1] + 1 || L.i[p + 1] != j + 1) return 1;
  if (lnz != L.nz[j + 2] + 2 || L.i[p + 2] != j + 2) return 2;
  return 3;
}

// The columns ldl_dltsolve solves at once down from column j (its chain test, as written there).
int backward_width(const Lview& L, int j) {
  const int lnz = L.nz[j];
  if (j < 4 || lnz != L.nz[j - 1] - 1 || L.i[L.p[j - 1] + 1] != j) return 1;
  if (lnz != L.nz[j - 2] - 2 || L.i[L.p[j - 2] + 2] != j) return 2;
  return 3;
}

// ldl_lsolve's step for the chain of `w` columns from j on X (n x K, row form), first half: the
// chain's own rows solved (its values y kept) and the positions of each column's first entry below
// the chain (p, q, r: the rows below come in the same order in the chain's columns).
template <int K>
struct ChainHead {
  double y[3][K];
  int p = 0, q = 0, r = 0;
};

template <int K>
ChainHead<K> chain_head(const Lview& L, double* X, int j, int w) {
  ChainHead<K> h;
  const int p0 = L.p[j];
  double* xj = X + std::size_t(j) * K;
  for (int c = 0; c < K; ++c) h.y[0][c] = xj[c];
  h.p = p0 + w;
  if (w == 1) return h;
  const int q0 = L.p[j + 1];
  for (int c = 0; c < K; ++c) h.y[1][c] = xj[K + c] - L.x[p0 + 1] * h.y[0][c];
  h.q = q0 + w - 1;
  if (w == 2) {
    for (int c = 0; c < K; ++c) xj[K + c] = h.y[1][c];
    return h;
  }
  for (int c = 0; c < K; ++c) h.y[2][c] = xj[2 * K + c] - L.x[p0 + 2] * h.y[0][c] - L.x[q0 + 1] * h.y[1][c];
  for (int c = 0; c < K; ++c) xj[K + c] = h.y[1][c], xj[2 * K + c] = h.y[2][c];
  h.r = L.p[j + 2] + 1;
  return h;
}

// Second half: for the rows below the chain at offsets [begin, end) (of the first column's entries
// after the chain), the term CHOLMOD subtracts from X[i] handed to sink(i, term) in the kernel's order
// (X[i] -= term is the kernel's operation: a - (b + c) with the sum as written there).
template <int K, int W, class Sink>
void chain_terms(const Lview& L, const ChainHead<K>& h, int begin, int end, Sink&& sink) {
  double t[K];
  for (int o = begin; o < end; ++o) {
    for (int c = 0; c < K; ++c) {
      if constexpr (W == 1) t[c] = L.x[h.p + o] * h.y[0][c];
      if constexpr (W == 2) t[c] = L.x[h.p + o] * h.y[0][c] + L.x[h.q + o] * h.y[1][c];
      if constexpr (W == 3) t[c] = L.x[h.p + o] * h.y[0][c] + L.x[h.q + o] * h.y[1][c] + L.x[h.r + o] * h.y[2][c];
    }
    sink(L.i[h.p + o], t);
  }
}

// The whole step: the rows below the chain before offset `split` to own(i, term), from it on to
// kept(i, term).
template <int K, class Own, class Kept>
void forward_chain(const Lview& L, double* X, int j, int w, int split, Own&& own, Kept&& kept) {
  const ChainHead<K> h = chain_head<K>(L, X, j, w);
  const int end = L.p[j] + L.nz[j] - h.p;
  if (w == 1) chain_terms<K, 1>(L, h, 0, split, own), chain_terms<K, 1>(L, h, split, end, kept);
  else if (w == 2) chain_terms<K, 2>(L, h, 0, split, own), chain_terms<K, 2>(L, h, split, end, kept);
  else chain_terms<K, 3>(L, h, 0, split, own), chain_terms<K, 3>(L, h, split, end, kept);
}

// ldl_dltsolve's step for the chain of `w` columns down from j on X (n x K, row form).
template <int K>
void backward_chain(const Lview& L, double* X, int j, int w) {
  const int p0 = L.p[j], pend = p0 + L.nz[j];
  double y[3][K];
  double* xj = X + std::size_t(j) * K;
  if (w == 1) {
    const double d = L.x[p0];
    for (int c = 0; c < K; ++c) y[0][c] = xj[c] / d;
    for (int p = p0 + 1; p < pend; ++p)
      for (int c = 0; c < K; ++c) y[0][c] -= L.x[p] * X[std::size_t(L.i[p]) * K + c];
    for (int c = 0; c < K; ++c) xj[c] = y[0][c];
    return;
  }
  const int q0 = L.p[j - 1], r0 = w == 3 ? L.p[j - 2] : 0;
  for (int c = 0; c < K; ++c) y[0][c] = xj[c] / L.x[p0], y[1][c] = xj[c - K] / L.x[q0];
  if (w == 3)
    for (int c = 0; c < K; ++c) y[2][c] = xj[c - 2 * K] / L.x[r0];
  for (int p = p0 + 1, q = q0 + 2, r = r0 + 3; p < pend; ++p, ++q, ++r) {
    const double* xi = X + std::size_t(L.i[p]) * K;
    for (int c = 0; c < K; ++c) y[0][c] -= L.x[p] * xi[c], y[1][c] -= L.x[q] * xi[c];
    if (w == 3)
      for (int c = 0; c < K; ++c) y[2][c] -= L.x[r] * xi[c];
  }
  for (int c = 0; c < K; ++c) {
    y[1][c] -= L.x[q0 + 1] * y[0][c];
    if (w == 3) y[2][c] -= L.x[r0 + 2] * y[0][c] + L.x[r0 + 1] * y[1][c];
    xj[c] = y[0][c], xj[c - K] = y[1][c];
    if (w == 3) xj[c - 2 * K] = y[2][c];
  }
}

// The elimination tree of L itself: each column's first row below the diagonal (-1: a root; CHOLMOD
// keeps every column's rows sorted, the diagonal first).
std::vector<int> factor_tree(const Lview& L) {
  std::vector<int> parent(std::size_t(L.n), -1);
  for (int j = 0; j < L.n; ++j)
    if (L.nz[j] > 1) parent[std::size_t(j)] = L.i[L.p[j] + 1];
  return parent;
}

// Each part column's top: the highest column of its part on its tree path (its part's subtree root).
std::vector<int> part_tops(const std::vector<int>& parent, const std::vector<std::uint8_t>& owner, std::uint8_t rest) {
  std::vector<int> top(parent.size(), -1);
  for (std::size_t j = parent.size(); j-- > 0;) {
    if (owner[j] == rest) continue;
    const int up = parent[j];
    top[j] = up >= 0 && owner[std::size_t(up)] == owner[j] ? top[std::size_t(up)] : int(j);
  }
  return top;
}

// The part of a chain's columns [lo, hi]: theirs when all share one part, else the rest (`rest`).
std::uint8_t chain_owner(const std::vector<std::uint8_t>& owner, int lo, int hi, std::uint8_t rest) {
  for (int j = lo + 1; j <= hi; ++j)
    if (owner[std::size_t(j)] != owner[std::size_t(lo)]) return rest;
  return owner[std::size_t(lo)];
}

}  // namespace

TreeSolve::TreeSolve(const cholmod_factor* L) {
  if (!L || L->is_super || L->is_ll || L->xtype != CHOLMOD_REAL || L->itype != CHOLMOD_INT || L->n < 8) return;
  const Lview v = view_of(L);
  const std::vector<int> parent = factor_tree(v);
  std::vector<double> work(std::size_t(v.n));
  for (int j = 0; j < v.n; ++j) work[std::size_t(j)] = v.nz[j];
  const RowSchedule s = schedule_rows(parent, work, kParts);
  std::vector<std::uint8_t> owner(std::size_t(v.n), kParts);
  for (int t = 0; t < kParts; ++t)
    for (int j : s.parts[std::size_t(t)]) owner[std::size_t(j)] = std::uint8_t(t);
  L_ = L;
  plan_chains(owner, part_tops(parent, owner, kParts));
  owner_ = std::move(owner);
}

// Both kernels' chains dealt to the parts and the rest; a part chain's rows below it split where the
// rest's begin (rows sorted: its part's rows are the tree path up to its top, the rest's lie above),
// with the runs the rest's forward stretch takes the parts' kept terms and its own chains in.
void TreeSolve::plan_chains(const std::vector<std::uint8_t>& owner, const std::vector<int>& top) {
  const Lview L = view_of(L_);
  for (int j = 0; j < L.n;) {
    const int w = forward_width(L, j);
    const std::uint8_t o = chain_owner(owner, j, j + w - 1, kParts);
    const int below = L.p[j] + w, end = L.p[j] + L.nz[j];
    int split = end - below;  // the rest's chains: every row below is their own
    if (o < kParts) {
      split = int(std::upper_bound(L.i + below, L.i + end, top[std::size_t(j)]) - (L.i + below));
      kept_[o] += std::size_t(end - below - split);
    }
    forward_[o].push_back({j, w, split});
    for (int c = j; c < j + w; ++c) (o < kParts ? part_entries_[o] : rest_entries_) += std::size_t(L.nz[c]);
    if (!runs_.empty() && runs_.back().source == o) ++runs_.back().count;
    else runs_.push_back({o, 1});
    j += w;
  }
  for (int j = L.n - 1; j >= 0;) {
    const int w = backward_width(L, j);
    backward_[chain_owner(owner, j - w + 1, j, kParts)].push_back({j, w, 0});
    j -= w;
  }
}

// A part's forward chains (ascending): its own rows updated, the rest's terms kept in `kept` (K each).
template <int K>
void TreeSolve::forward_part(int part, double* Y, double* kept) const {
  const Lview L = view_of(L_);
  const auto own = [Y](int i, const double* t) {
    double* yi = Y + std::size_t(i) * K;
    for (int c = 0; c < K; ++c) yi[c] -= t[c];
  };
  const auto keep = [&kept](int, const double* t) {
    for (int c = 0; c < K; ++c) kept[c] = t[c];
    kept += K;
  };
  for (const Chain& ch : forward_[part]) forward_chain<K>(L, Y, ch.first, ch.width, ch.split, own, keep);
}

// The rest's rows: the parts' kept terms and the rest's chains in ascending column order.
template <int K>
void TreeSolve::forward_rest(double* Y, const double* kept0, const double* kept1) const {
  const Lview L = view_of(L_);
  const double* kept[kParts] = {kept0, kept1};
  std::size_t next[kParts + 1] = {0, 0, 0};
  const auto apply = [Y](int i, const double* t) {
    double* yi = Y + std::size_t(i) * K;
    for (int c = 0; c < K; ++c) yi[c] -= t[c];
  };
  for (const Run& run : runs_) {
    const std::vector<Chain>& chains = forward_[run.source];
    for (std::size_t m = 0; m < run.count; ++m) {
      const Chain& ch = chains[next[run.source]++];
      if (run.source == kParts) {
        forward_chain<K>(L, Y, ch.first, ch.width, ch.split, apply, apply);
        continue;
      }
      const double*& t = kept[run.source];
      for (int p = L.p[ch.first] + ch.width + ch.split; p < L.p[ch.first] + L.nz[ch.first]; ++p, t += K) apply(L.i[p], t);
    }
  }
}

template <int K>
void TreeSolve::backward(const std::vector<Chain>& chains, double* Y) const {
  const Lview L = view_of(L_);
  for (const Chain& ch : chains) backward_chain<K>(L, Y, ch.first, ch.width);
}

template <int K>
void TreeSolve::solve_k(double* Y) const {
  std::vector<double> kept[kParts];
  for (int t = 0; t < kParts; ++t) kept[t].resize(kept_[t] * K);
  parallel_tasks({[&] { forward_part<K>(0, Y, kept[0].data()); }, [&] { forward_part<K>(1, Y, kept[1].data()); }});
  forward_rest<K>(Y, kept[0].data(), kept[1].data());
  backward<K>(backward_[kParts], Y);
  parallel_tasks({[&] { backward<K>(backward_[0], Y); }, [&] { backward<K>(backward_[1], Y); }});
}

void TreeSolve::solve(double* Y, int k) const {
  if (k == 1) solve_k<1>(Y);
  else if (k == 2) solve_k<2>(Y);
  else solve_k<3>(Y);
}

}  // namespace cf::flat_detail
#endif
