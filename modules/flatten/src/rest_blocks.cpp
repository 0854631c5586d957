// The threaded factorisation's rest computed in blocks (see rest_blocks.h).
#include "rest_blocks.h"

#ifdef COLONFLAT_HAVE_CHOLMOD
#include <Eigen/Dense>

#include <algorithm>

#include "colonflat/core/run_stats.h"
#include "colonflat/core/threads.h"
#include "threaded_factor.h"

namespace cf::flat_detail {

namespace {

// One row k of the rest after step 1.
struct RestRow {
  std::vector<int> cols;     // its columns in P (the solve's pattern, as cholmod_solve2 gives it)
  std::vector<double> vals;  // L(k, cols)
  std::vector<int> root;     // its columns in R below the diagonal, as indices into `rest`, ascending
};

// local[k] = row k's index in `rest`, -1 for the rows of P.
std::vector<int> local_index(std::size_t n, const std::vector<int>& rest) {
  std::vector<int> local(n, -1);
  for (std::size_t r = 0; r < rest.size(); ++r) local[std::size_t(rest[r])] = int(r);
  return local;
}

// Row k's columns in R (row.root): the tree paths from the rows i < k of upper's column k up to k.
// `mark`: n entries, none equal to k on entry (the caller's rows are distinct).
void root_pattern(const cholmod_sparse* upper, const std::vector<int>& parent, const std::vector<int>& local, int k,
                  std::vector<int>& mark, RestRow& row) {
  const int* Ap = static_cast<const int*>(upper->p);
  const int* Ai = static_cast<const int*>(upper->i);
  mark[std::size_t(k)] = k;
  for (int p = Ap[k]; p < Ap[k + 1]; ++p)
    for (int i = Ai[p]; i >= 0 && i < k && mark[std::size_t(i)] != k; i = parent[std::size_t(i)]) {
      mark[std::size_t(i)] = k;
      if (local[std::size_t(i)] >= 0) row.root.push_back(local[std::size_t(i)]);
    }
  std::sort(row.root.begin(), row.root.end());
}

// Step 1 on one thread: L(k, P)^T = (L_PP D_P)^-1 A(P, k) by cholmod_solve2 with its own common and
// reused right-hand side, pattern and workspaces.
class RowSolver {
 public:
  RowSolver(cholmod_factor* L, std::size_t max_column) : L_(L) {
    B_ = cholmod_zeros(L->n, 1, CHOLMOD_REAL, &tc_.c);
    Bset_ = cholmod_allocate_sparse(L->n, 1, std::max<std::size_t>(max_column, 1), 1, 1, 0, CHOLMOD_PATTERN, &tc_.c);
  }
  ~RowSolver() {
    cholmod_free_dense(&B_, &tc_.c), cholmod_free_dense(&X_, &tc_.c), cholmod_free_dense(&Y_, &tc_.c);
    cholmod_free_dense(&E_, &tc_.c), cholmod_free_sparse(&Bset_, &tc_.c), cholmod_free_sparse(&Xset_, &tc_.c);
  }
  RowSolver(const RowSolver&) = delete;
  RowSolver& operator=(const RowSolver&) = delete;

  // Row k's entries in the columns of P into row.cols / row.vals; false when CHOLMOD failed.
  bool solve(const cholmod_sparse* upper, const std::vector<int>& local, int k, RestRow& row) {
    if (!B_ || !Bset_) return false;
    const int* Ap = static_cast<const int*>(upper->p);
    const int* Ai = static_cast<const int*>(upper->i);
    const double* Ax = static_cast<const double*>(upper->x);
    int* Bi = static_cast<int*>(Bset_->i);
    double* b = static_cast<double*>(B_->x);
    int count = 0;
    for (int p = Ap[k]; p < Ap[k + 1]; ++p)
      if (Ai[p] < k && local[std::size_t(Ai[p])] < 0) Bi[count++] = Ai[p], b[Ai[p]] = Ax[p];
    static_cast<int*>(Bset_->p)[1] = count;
    if (count == 0) return true;  // no entry in P
    const bool ok = cholmod_solve2(CHOLMOD_LD, L_, B_, Bset_, &X_, &Xset_, &Y_, &E_, &tc_.c) && tc_.c.status >= CHOLMOD_OK;
    for (int t = 0; t < count; ++t) b[Bi[t]] = 0.0;
    if (!ok) return false;
    const int* Xi = static_cast<const int*>(Xset_->i);
    const double* x = static_cast<const double*>(X_->x);
    row.cols.assign(Xi, Xi + static_cast<const int*>(Xset_->p)[1]);
    row.vals.resize(row.cols.size());
    for (std::size_t t = 0; t < row.cols.size(); ++t) row.vals[t] = x[row.cols[t]];
    return true;
  }

 private:
  ThreadCommon tc_;
  cholmod_factor* L_;
  cholmod_dense *B_ = nullptr, *X_ = nullptr, *Y_ = nullptr, *E_ = nullptr;
  cholmod_sparse *Bset_ = nullptr, *Xset_ = nullptr;
};

// Step 1 for every row of the rest, the rows dealt round-robin to the threads (a row's result does
// not depend on who computes it), with each row's pattern in R.
bool solve_rows(const cholmod_sparse* upper, const std::vector<int>& parent, const std::vector<int>& rest,
                const std::vector<int>& local, cholmod_factor* L, std::vector<RestRow>& rows) {
  const int* Ap = static_cast<const int*>(upper->p);
  std::size_t max_column = 0;
  for (int k : rest) max_column = std::max(max_column, std::size_t(Ap[k + 1] - Ap[k]));
  const std::size_t threads = std::size_t(std::max(1, thread_count()));
  std::vector<char> ok(threads, 1);
  rows.assign(rest.size(), RestRow{});
  parallel_for(threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t t = begin; t < end; ++t) {
      RowSolver solver(L, max_column);
      std::vector<int> mark(L->n, -1);
      for (std::size_t r = t; r < rest.size() && ok[t]; r += threads) {
        ok[t] = solver.solve(upper, local, rest[r], rows[r]);
        root_pattern(upper, parent, local, rest[r], mark, rows[r]);
      }
    }
  });
  return std::count(ok.begin(), ok.end(), 1) == std::ptrdiff_t(threads);
}

// L_RP by columns of P: column j's entries start[j] .. start[j + 1] of `loc` (indices into `rest`,
// ascending) and `val`.
struct PartColumns {
  std::vector<int> start, loc, used;  // used: the columns of P with entries, ascending
  std::vector<int> run_end;           // per entry t: the end of its column's run of consecutive loc from t on
  std::vector<double> val;
};

// c.run_end: runs of consecutive rows of R in each column (a separator's rows are consecutive: the
// Schur complement's updates then run over contiguous memory).
void find_runs(PartColumns& c) {
  c.run_end.resize(c.loc.size());
  for (int j : c.used)
    for (int t = c.start[std::size_t(j) + 1] - 1, end = t + 1; t >= c.start[std::size_t(j)]; --t) {
      if (t + 1 < end && c.loc[std::size_t(t) + 1] != c.loc[std::size_t(t)] + 1) end = t + 1;
      c.run_end[std::size_t(t)] = end;
    }
}

// (Each row's cols and vals are given back once copied: only its root pattern is read after.)
PartColumns part_columns(std::size_t n, std::vector<RestRow>& rows) {
  PartColumns c;
  c.start.assign(n + 1, 0);
  for (const RestRow& row : rows)
    for (int j : row.cols) ++c.start[std::size_t(j) + 1];
  for (std::size_t j = 0; j < n; ++j) {
    if (c.start[j + 1] > 0) c.used.push_back(int(j));
    c.start[j + 1] += c.start[j];
  }
  c.loc.resize(std::size_t(c.start[n]));
  c.val.resize(c.loc.size());
  std::vector<int> fill(c.start.begin(), c.start.end() - 1);
  for (std::size_t r = 0; r < rows.size(); ++r)  // rows ascending: each column's entries ascending
    for (std::size_t t = 0; t < rows[r].cols.size(); ++t) {
      const int at = fill[std::size_t(rows[r].cols[t])]++;
      c.loc[std::size_t(at)] = int(r);
      c.val[std::size_t(at)] = rows[r].vals[t];
    }
  for (RestRow& row : rows) std::vector<int>().swap(row.cols), std::vector<double>().swap(row.vals);
  find_runs(c);
  return c;
}

// L(R, P) appended to L's columns of P (after the rows of P, as cholmod_rowfac would); false when a
// column has no room.
bool append_part_entries(const PartColumns& c, const std::vector<int>& rest, cholmod_factor* L) {
  const int* Lp = static_cast<const int*>(L->p);
  const int* next = static_cast<const int*>(L->next);
  int* Li = static_cast<int*>(L->i);
  int* Lnz = static_cast<int*>(L->nz);
  double* Lx = static_cast<double*>(L->x);
  for (int j : c.used) {
    const int b = c.start[std::size_t(j)], e = c.start[std::size_t(j) + 1];
    const int at = Lp[j] + Lnz[j];
    if (at + (e - b) > Lp[next[j]]) return false;
    for (int t = b; t < e; ++t) Li[at + t - b] = rest[std::size_t(c.loc[std::size_t(t)])], Lx[at + t - b] = c.val[std::size_t(t)];
    Lnz[j] += e - b;
  }
  return true;
}

// A_RR's lower triangle into S (m x m, zero elsewhere).
Eigen::MatrixXd root_block(const cholmod_sparse* upper, const std::vector<int>& rest, const std::vector<int>& local) {
  const int* Ap = static_cast<const int*>(upper->p);
  const int* Ai = static_cast<const int*>(upper->i);
  const double* Ax = static_cast<const double*>(upper->x);
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(Eigen::Index(rest.size()), Eigen::Index(rest.size()));
  for (std::size_t r = 0; r < rest.size(); ++r)
    for (int p = Ap[rest[r]]; p < Ap[rest[r] + 1]; ++p)
      if (local[std::size_t(Ai[p])] >= 0) S(Eigen::Index(r), local[std::size_t(Ai[p])]) = Ax[p];
  return S;
}

// The columns of S split into `threads` ranges of about equal update work (first column of each, and m).
std::vector<int> schur_ranges(const PartColumns& c, int m, int threads) {
  std::vector<double> work(std::size_t(m), 0.0);
  double total = 0;
  for (int j : c.used)
    for (int t = c.start[std::size_t(j)], e = c.start[std::size_t(j) + 1]; t < e; ++t)
      work[std::size_t(c.loc[std::size_t(t)])] += double(e - t), total += double(e - t);
  std::vector<int> first{0};
  double sum = 0;
  for (int a = 0; a < m && int(first.size()) < threads; ++a)
    if ((sum += work[std::size_t(a)]) >= total * double(first.size()) / double(threads)) first.push_back(a + 1);
  while (int(first.size()) <= threads) first.push_back(m);
  first.back() = m;
  return first;
}

// Step 2: S -= d_j l_j l_j^T for every column j of P, ascending j, on the threads; each thread owns
// the columns [first[t], first[t + 1]) of S (an entry's terms come in the same order for any split).
void subtract_part_terms(const PartColumns& c, const cholmod_factor* L, Eigen::MatrixXd& S) {
  const int* Lp = static_cast<const int*>(L->p);
  const double* Lx = static_cast<const double*>(L->x);
  const std::vector<int> first = schur_ranges(c, int(S.cols()), std::max(1, thread_count()));
  parallel_for(first.size() - 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t t = begin; t < end; ++t)
      for (int j : c.used) {
        const int* loc = c.loc.data();
        const int e = c.start[std::size_t(j) + 1];
        int a = int(std::lower_bound(loc + c.start[std::size_t(j)], loc + e, first[t]) - loc);
        const double d = Lx[Lp[j]];
        for (; a < e && loc[a] < first[t + 1]; ++a) {
          const double w = d * c.val[std::size_t(a)];
          double* col = S.col(loc[a]).data();
          for (int b = a; b < e; b = c.run_end[std::size_t(b)]) {  // each run: contiguous in S and in val
            double* to = col + loc[b];
            const double* v = c.val.data() + b;
            for (int i = 0, len = c.run_end[std::size_t(b)] - b; i < len; ++i) to[i] -= v[i] * w;
          }
        }
      }
  });
}

// Step 3: S's dense LLT = L_RR D_R^(1/2), written into L's columns of R; false when S is not positive definite.
bool factor_root(Eigen::MatrixXd& S, const std::vector<RestRow>& rows, const std::vector<int>& rest, cholmod_factor* L) {
  Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>, Eigen::Lower> llt(S);
  if (llt.info() != Eigen::Success) return false;
  const int* Lp = static_cast<const int*>(L->p);
  const int* next = static_cast<const int*>(L->next);
  int* Li = static_cast<int*>(L->i);
  int* Lnz = static_cast<int*>(L->nz);
  double* Lx = static_cast<double*>(L->x);
  for (std::size_t c = 0; c < rest.size(); ++c) Lx[Lp[rest[c]]] = S(Eigen::Index(c), Eigen::Index(c)) * S(Eigen::Index(c), Eigen::Index(c));
  for (std::size_t r = 0; r < rows.size(); ++r)
    for (int c : rows[r].root) {
      const int j = rest[std::size_t(c)], at = Lp[j] + Lnz[j]++;
      if (at >= Lp[next[j]]) return false;
      Li[at] = rest[r];
      Lx[at] = S(Eigen::Index(r), c) / S(c, c);
    }
  return true;
}

}  // namespace

bool factor_rest_in_blocks(cholmod_sparse* upper, const std::vector<int>& parent, const std::vector<int>& rest,
                           cholmod_factor* L, RestBlockWall* wall) {
  RestBlockWall w;
  Stopwatch lap;
  const std::vector<int> local = local_index(L->n, rest);
  std::vector<RestRow> rows;
  bool ok = solve_rows(upper, parent, rest, local, L, rows);
  w.solves = lap.lap();
  const PartColumns c = ok ? part_columns(L->n, rows) : PartColumns{};
  ok = ok && append_part_entries(c, rest, L);
  w.copy = lap.lap();
  Eigen::MatrixXd S;
  if (ok) {
    S = root_block(upper, rest, local);
    subtract_part_terms(c, L, S);
  }
  w.schur = lap.lap();
  ok = ok && factor_root(S, rows, rest, L);
  w.root = lap.lap();
  if (ok) L->minor = L->n;
  w.rows = rest.size();
  w.entries_from_parts = c.loc.size();
  if (wall) *wall = w;
  return ok;
}

}  // namespace cf::flat_detail
#endif
