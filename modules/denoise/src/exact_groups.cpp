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
#include <cstdio>
#include <cstdlib>

#include "colonflat/core/run_stats.h"
#include "exact_greedy.h"

namespace cf::detail {

// Pending sources (active, not exact, bound < best, own group radius >= radius) of the seed's
// family connected to it by mesh edges within `radius` mm along the tree grown breadth-first
// from it. Returns member slots, seed first, parents before children; root_parent[i] = the
// halfedge from member i's parent (-1 for the seed). Marks the members in group_mark_.
std::vector<int> ExactGreedy::collect_group(int seed, double best, double radius, std::vector<int>* root_parent) {
  const Family& fam = families_[slots_[seed].family];
  if (group_mark_.size() < st_.mesh.n_vertices()) group_mark_.resize(st_.mesh.n_vertices(), 0);
  if (++group_stamp_ == 0) {
    std::fill(group_mark_.begin(), group_mark_.end(), 0);
    group_stamp_ = 1;
  }
  std::vector<int> members{seed};
  std::vector<double> reach{0.0};
  root_parent->assign(1, -1);
  group_mark_[slots_[seed].vertex] = group_stamp_;
  for (std::size_t i = 0; i < members.size(); ++i) {
    const auto v = Mesh::VertexHandle(slots_[members[i]].vertex);
    for (auto h : st_.mesh.voh_range(v)) {
      const int w = st_.mesh.to_vertex_handle(h).idx();
      if (group_mark_[w] == group_stamp_ || w >= static_cast<int>(fam.slot_of.size()) || fam.slot_of[w] < 0) continue;
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

// One search from the group around `seed` (best = the best known loop's value), or a single
// search when the group is the seed alone.
void ExactGreedy::search_group(int seed, double best) {
  const double radius = slots_[seed].group_radius >= 0 ? slots_[seed].group_radius : kGroupRadius * best;
  std::vector<int> root_parent;
  const std::vector<int> members = radius > 0 ? collect_group(seed, best, radius, &root_parent) : std::vector<int>{seed};
  if (members.size() < 2) {
    search_from(seed, search_limit(seed));
    return;
  }
  Stopwatch sw;
  const int family = slots_[seed].family;
  search_->set_cochain(family == 0 ? nullptr : &families_[family].cochain);
  std::vector<int> roots;
  for (int m : members) roots.push_back(slots_[m].vertex);
  const double limit = search_limit(seed);
  const CycleCandidate c = search_->run_group(roots, root_parent, limit);
  ++searches_;
  ++group_searches_;
  group_members_ += static_cast<long long>(members.size());
  settled_ += static_cast<long long>(search_->last_settled());
  largest_limit_ = std::max(largest_limit_, limit);
  slots_[seed].own_limit = limit;
  const double own = c.found ? c.value : c.truncated ? limit : kInf;
  settle_group(members, c, own, best, radius);
  if (std::getenv("DENOISE_TRACE")) std::fprintf(stderr, "G fam %d cross %d members %zu radius %.2f limit %.2f best %.2f own %.3f settled %zu\n", family, int(crossing_), members.size(), radius, limit, best, own, search_->last_settled());
  if (crossing_ && families_.size() == 2 && c.found) add_transversal_family(c);  // Z
  st_.t.search += sw.seconds();
}

// Bounds after a group search of value `own`: F >= own for every member, F >= own - 2d for
// the family's sources settled at distance d from the group, F = own for the root the cycle
// passes through when it uses no tree edge. Members still below `best` are searched next in
// groups of half the radius (down to single searches).
void ExactGreedy::settle_group(const std::vector<int>& members, const CycleCandidate& c, double own, double best,
                               double radius) {
  const int seed = members.front();
  spread_bounds(seed, own);
  if (slots_[seed].bound.value < own) set_bound(seed, SourceBound{own, false, slots_[seed].vertex, 0});
  if (c.found) {
    const std::vector<Mesh::VertexHandle> loop = search_->extract(c);
    const int first = loop.front().idx();
    const std::vector<int>& slot_of = families_[slots_[seed].family].slot_of;
    const bool real = std::abs(loop_length(st_.mesh, loop) - own) <= 1e-9 * (1.0 + own);
    if (real && group_mark_[first] == group_stamp_ && slot_of[first] >= 0) {
      set_bound(slot_of[first], SourceBound{own, true, first, 0});
      ++group_exact_;
    }
  }
  if (!(own < best)) return;
  const double half = 0.5 * radius < st_.mean_edge ? 0.0 : 0.5 * radius;
  for (int m : members)
    if (!slots_[m].bound.exact) slots_[m].group_radius = half;
}

}  // namespace cf::detail
