// The update of a conformal solve's factorisation to the part of its surface that remains after
// side branches are cut off (conformal_factor.h). On the 1.39 M-face CTC colon: about 200 rank-one
// terms, a fraction of a second, against 3 s for a new factorisation (docs/flatten.md, "Speed").
#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "colonflat/core/run_stats.h"
#include "colonflat/core/union_find.h"
#include "conformal_factor.h"
#include "factor_schedule.h"  // thread_cpu_seconds

namespace cf::flat_detail {
namespace {

// Per edge of f's surface: its weight minus its weight on the remaining surface (all of it when
// the edge is gone). Edges whose faces all remain change by exactly 0 (the same cotangent terms
// summed in the same face order). False when an edge of the remaining surface is not one of f's.
bool weight_changes(const ConformalFactor& f, const Edges& E, const std::vector<double>& w,
                    const std::vector<int>& old_of, std::vector<double>& change) {
  const std::size_t nv = f.unknown_of.size();
  std::vector<int> first(nv + 1, 0);  // f's edges with lower vertex lo: [first[lo], first[lo + 1])
  for (const auto& e : f.edges) ++first[std::size_t(e[0]) + 1];
  for (std::size_t v = 0; v < nv; ++v) first[v + 1] += first[v];
  change = f.weights;
  for (std::size_t e = 0; e < E.ev.size(); ++e) {
    const int a = old_of[E.ev[e][0]], b = old_of[E.ev[e][1]];
    const int lo = std::min(a, b), hi = std::max(a, b);
    int k = first[lo];
    while (k < first[lo + 1] && f.edges[k][1] != hi) ++k;
    if (k == first[lo + 1]) return false;
    change[k] -= w[e];
  }
  return true;
}

// Rank-one terms as the columns of C (C C^T added or taken away): sqrt(|change|) (e_a - e_b) over
// v's unknowns (the pinned vertex has none).
struct RankOneColumns {
  std::vector<Eigen::Triplet<double>> entries;
  int columns = 0;
  void add(int unknown_a, int unknown_b, double scale) {
    if (unknown_a < 0 && unknown_b < 0) return;
    if (unknown_a >= 0) entries.emplace_back(unknown_a, columns, scale);
    if (unknown_b >= 0) entries.emplace_back(unknown_b, columns, -scale);
    ++columns;
  }
  SpdSolver::SpMat matrix(int rows) const {
    SpdSolver::SpMat C(rows, columns);
    C.setFromTriplets(entries.begin(), entries.end());
    return C;
  }
};

// Terms that grow the matrix (weights that rise, one grounding term per piece of cut-off vertices,
// its vertex's weight sum) and terms that shrink it (weights that fall: the cut-off faces' terms).
void rank_one_terms(const ConformalFactor& f, const std::vector<double>& change, const std::vector<int>& new_of_old,
                    RankOneColumns& grow, RankOneColumns& shrink) {
  const std::size_t nv = f.unknown_of.size();
  UnionFind pieces(nv);
  std::vector<double> weight_sum(nv, 0.0);
  for (std::size_t e = 0; e < f.edges.size(); ++e) {
    const int a = f.edges[e][0], b = f.edges[e][1];
    weight_sum[a] += std::abs(f.weights[e]), weight_sum[b] += std::abs(f.weights[e]);
    if (new_of_old[a] < 0 && new_of_old[b] < 0) {
      pieces.unite(std::uint32_t(a), std::uint32_t(b));
    } else if (change[e] != 0) {
      (change[e] < 0 ? grow : shrink).add(f.unknown_of[a], f.unknown_of[b], std::sqrt(std::abs(change[e])));
    }
  }
  std::vector<char> grounded(nv, 0);
  for (std::size_t v = 0; v < nv; ++v) {
    char& done = grounded[pieces.find(std::uint32_t(v))];
    if (new_of_old[v] < 0 && !done) done = 1, grow.add(f.unknown_of[v], -1, std::sqrt(std::max(weight_sum[v], 1e-300)));
  }
}

// The loops of the remaining surface are f's (the same vertices, the same ends).
bool same_loops(const ConformalFactor& f, const std::vector<char>& mark, const std::vector<int>& new_of_old) {
  for (std::size_t v = 0; v < f.mark.size(); ++v)
    if (f.mark[v] && (new_of_old[v] < 0 || mark[new_of_old[v]] != f.mark[v])) return false;
  auto on_loops = [](const std::vector<char>& m) { return m.size() - std::size_t(std::count(m.begin(), m.end(), 0)); };
  return on_loops(mark) == on_loops(f.mark);
}

}  // namespace

// The update is used while its estimated operations stay below this share of the first
// factorisation's (session 31 "update", docs/history/flatten.md): the update runs on one thread
// at ~0.45 x a factorisation's time per counted flop (the estimate counts every column on each
// term's path; CHOLMOD takes up to 8 terms at a time along shared paths), a new factorisation on
// two threads and on the smaller remaining surface (0.4-1 x the first's flops). Measured on the
// stress rows (estimate / first factorisation -> wall of the update / of the new factorisation):
// 0.07 -> 0.05, 0.39 -> 0.14, 0.49 -> 0.11, 0.74 -> 0.54, 0.95 -> 0.44, 1.10 -> 0.47;
// 1.27 -> 1.42, 1.50 -> 1.31, 1.83 -> 1.07, 3.46 -> 3.4. At 1 every update taken was >= 1.8 x
// cheaper; of those refused only 1.10 (an 80 k-unknown band, 0.5 s) would have been cheaper.
constexpr double kUpdateShareOfFactorisation = 1.0;

bool update_is_cheaper(double estimated_update_flops, double factorisation_flops) {
  return estimated_update_flops <= kUpdateShareOfFactorisation * factorisation_flops;
}

namespace {

// COLONFLAT_FLATTEN_DEBUG: why the update is not tried.
bool refuse(const char* why) {
  if (std::getenv("COLONFLAT_FLATTEN_DEBUG")) std::fprintf(stderr, "flatten debug factor update refused: %s\n", why);
  return false;
}

}  // namespace

bool restrict_factor(ConformalFactor& f, const Edges& E, const std::vector<double>& w, const std::vector<char>& mark,
                     const std::vector<int>& new_of_old) {
  if (new_of_old.size() != f.unknown_of.size() || !same_loops(f, mark, new_of_old)) return refuse("not the same loops");
  std::vector<int> old_of(mark.size(), -1);
  for (std::size_t v = 0; v < new_of_old.size(); ++v)
    if (new_of_old[v] >= 0) old_of[new_of_old[v]] = int(v);
  if (std::count(old_of.begin(), old_of.end(), -1) > 0) return refuse("vertices that are not the factor's");
  std::vector<double> change;
  if (!weight_changes(f, E, w, old_of, change)) return refuse("edges that are not the factor's");
  RankOneColumns grow, shrink;
  rank_one_terms(f, change, new_of_old, grow, shrink);
  // Many terms, or paths through the dense columns of the loops (ordered last): a new factorisation.
  const int n = int(f.unknown_of.size()) - 1;
  const SpdSolver::SpMat up = grow.matrix(n), down = shrink.matrix(n);
  const double factor_flops = f.solver.factor_flops();
  const double cost = f.solver.modify_flops({&up, &down}, kUpdateShareOfFactorisation * factor_flops);
  const bool cheaper = update_is_cheaper(cost, factor_flops), debug = std::getenv("COLONFLAT_FLATTEN_DEBUG") != nullptr;
  if (debug)
    std::fprintf(stderr, "flatten debug factor update: %d rank-one terms, about %.3g flops against %.3g for a new factorisation (%.3f): %s\n",
                 grow.columns + shrink.columns, cost, factor_flops, cost / factor_flops, cheaper ? "updated" : "refused, too dear");
  if (!cheaper) return false;
  const Stopwatch sw;
  const double cpu = thread_cpu_seconds();
  const bool ok = f.solver.modify(up, true) && f.solver.modify(down, false);
  if (debug) std::fprintf(stderr, "flatten debug factor update done: %.2f s, %.2f CPU s\n", sw.seconds(), thread_cpu_seconds() - cpu);
  return ok;
}

}  // namespace cf::flat_detail
