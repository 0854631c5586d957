// Group searches of the exact method (exact_greedy.h): the sources still to certify against the
// best known loop are searched as connected groups, one multi-root Dijkstra per group
// (FundamentalCycleSearch::run_group), instead of one search per source. Exactness does not
// depend on the grouping: a group search gives every member a lower bound of its F (or its
// exact F, for the root its cycle passes through), and the greedy only cuts an exact entry at
// the top of the queue. What the grouping buys: on a straight tube every meridian has the same
// length U, so every source on it has F = U and no bound from a neighbour's search can certify
// it (F(t) >= F(c) - 2 d(c, t) < U); a search from the whole stretch of sources, its tree edges
// counted as length 0, gives each of them F >= U at the cost of about two single searches.
#include <algorithm>
#include <cmath>

#include "colonflat/core/run_stats.h"
#include "exact_greedy.h"

namespace cf::detail {

// Pending sources (active, not exact, bound < best, own group radius >= radius) of the seed's
// family connected to it by mesh edges within `radius` mm along the tree grown breadth-first
// from it, none marked `taken` (another group of this round). Returns member slots, seed first,
// parents before children; root_parent[i] = the halfedge from member i's parent (-1 for the
// seed). Marks the members with a new group_stamp_.
std::vector<int> ExactGreedy::collect_group(int seed, double best, double radius, std::uint32_t taken,
                                            std::vector<int>* root_parent) {
  const Family& fam = families_[slots_[seed].family];
  if (group_mark_.size() < st_.mesh.n_vertices()) group_mark_.resize(st_.mesh.n_vertices(), 0);
  if (++group_stamp_ == 0 || (taken != 0 && group_stamp_ < taken)) {  // wrapped
    std::fill(group_mark_.begin(), group_mark_.end(), 0);
    group_stamp_ = 1;
    taken = 0;
  }
  std::vector<int> members{seed};
  std::vector<double> reach{0.0};
  root_parent->assign(1, -1);
  group_mark_[slots_[seed].vertex] = group_stamp_;
  for (std::size_t i = 0; i < members.size() && radius > 0; ++i) {
    const auto v = Mesh::VertexHandle(slots_[members[i]].vertex);
    for (auto h : st_.mesh.voh_range(v)) {
      const int w = st_.mesh.to_vertex_handle(h).idx();
      if (group_mark_[w] == group_stamp_ || (taken != 0 && group_mark_[w] == taken)) continue;
      if (w >= static_cast<int>(fam.slot_of.size()) || fam.slot_of[w] < 0) continue;
      const Slot& slot = slots_[fam.slot_of[w]];
      if (!slot.active || slot.bound.exact || !(slot.bound.value < best)) continue;
      if (slot.group_radius >= 0 && slot.group_radius < radius) continue;  // failed in a larger group
      const double r = reach[i] + st_.mesh.calc_edge_length(h);
      if (r > radius) continue;
      group_mark_[w] = group_stamp_;
      members.push_back(fam.slot_of[w]);
      reach.push_back(r);
      root_parent->push_back(h.idx());
    }
  }
  return members;
}

ExactGreedy::GroupRun ExactGreedy::prepare_group(int seed, double best, std::uint32_t taken) {
  GroupRun g;
  g.seed = seed;
  g.radius = slots_[seed].group_radius >= 0 ? slots_[seed].group_radius : kGroupRadius * best;
  g.members = collect_group(seed, best, g.radius, taken, &g.root_parent);
  for (int m : g.members) g.roots.push_back(slots_[m].vertex);
  g.limit = search_limit(seed);
  return g;
}

// One search from the group around `seed` (best = the best known loop's value) and, with two
// threads and large searches, at the same time one from a second group far from it.
void ExactGreedy::search_group(int seed, double best) {
  Stopwatch sw;
  std::vector<GroupRun> runs{prepare_group(seed, best, 0)};
  const bool pair = worker_ && last_group_settled_ >= kParallelFrom && !(crossing_ && families_.size() == 2);
  if (pair) {
    const std::uint32_t first = group_stamp_;
    const int other = second_seed(seed, best, first);
    if (other >= 0) runs.push_back(prepare_group(other, best, first));
  }
  run_groups(runs);
  last_group_settled_ = search_->last_settled();
  for (std::size_t i = 0; i < runs.size(); ++i) finish_group(runs[i], i == 0 ? *search_ : *search2_, best);
  st_.t.search += sw.seconds();
}

// The next farthest pending source outside the group marked `taken`, else the pending source
// of the seed's family farthest (in space) from the seed, or -1. Sources the far-first order
// skips stay pending: they are searched later in the smallest-bound order.
int ExactGreedy::second_seed(int seed, double best, std::uint32_t taken) {
  for (int s = farthest_pending(best); s >= 0; s = farthest_pending(best))
    if (group_mark_[slots_[s].vertex] != taken) return s;
  const Vec3& from = st_.mesh.point(Mesh::VertexHandle(slots_[seed].vertex));
  int other = -1;
  double farthest = -1;
  for (int s : active_) {
    const Slot& slot = slots_[s];
    if (!slot.active || slot.bound.exact || !(slot.bound.value < best) || slot.family != slots_[seed].family) continue;
    if (group_mark_[slot.vertex] == taken) continue;
    const double d = (st_.mesh.point(Mesh::VertexHandle(slot.vertex)) - from).sqrnorm();
    if (d > farthest) farthest = d, other = s;
  }
  return other;
}

void ExactGreedy::run_groups(std::vector<GroupRun>& runs) {
  auto run = [this, &runs](std::size_t i) {
    GroupRun& g = runs[i];
    FundamentalCycleSearch& search = i == 0 ? *search_ : *search2_;
    const int family = slots_[g.seed].family;
    search.set_cochain(family == 0 ? nullptr : &families_[family].cochain);
    g.result = search.run_group(g.roots, g.root_parent, g.limit);
  };
  if (runs.size() == 1) return run(0);
  ++parallel_pairs_;
  worker_->run_both([&] { run(0); }, [&] { run(1); });
}

// Bounds after a group search of value `own`: F >= own for every member, F >= own - 2d for
// the family's sources settled at distance d from the group, F = own for the root both tree
// paths of the cycle lead to (a real closed walk through it). Members still below `best` are
// searched next in groups of half the radius (down to single searches).
void ExactGreedy::finish_group(const GroupRun& g, FundamentalCycleSearch& search, double best) {
  const CycleCandidate& c = g.result;
  ++searches_;
  group_searches_ += g.members.size() > 1;
  group_members_ += g.members.size() > 1 ? static_cast<long long>(g.members.size()) : 0;
  settled_ += static_cast<long long>(search.last_settled());
  largest_limit_ = std::max(largest_limit_, g.limit);
  slots_[g.seed].own_limit = g.limit;
  const double own = c.found ? c.value : c.truncated ? g.limit : kInf;
  spread_bounds(g.seed, own, search);
  if (slots_[g.seed].bound.value < own) set_bound(g.seed, SourceBound{own, false, slots_[g.seed].vertex, 0});
  const std::vector<int>& slot_of = families_[slots_[g.seed].family].slot_of;
  if (c.found) {
    const int root = search.root_of(c.u.idx());
    if (root == search.root_of(c.v.idx()) && root < static_cast<int>(slot_of.size()) && slot_of[root] >= 0 &&
        slots_[slot_of[root]].active) {
      set_bound(slot_of[root], SourceBound{own, true, root, 0});
      group_exact_ += g.members.size() > 1;
    }
  }
  if (crossing_ && families_.size() == 2 && c.found) add_transversal_family(c);  // Z (run 0 only)
  if (!(own < best) || g.members.size() < 2) return;
  const double half = 0.5 * g.radius < st_.mean_edge ? 0.0 : 0.5 * g.radius;
  for (int m : g.members)
    if (!slots_[m].bound.exact) slots_[m].group_radius = half;
}

}  // namespace cf::detail
