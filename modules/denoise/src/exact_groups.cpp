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
#include <atomic>
#include <cmath>

#include "colonflat/core/run_stats.h"
#include "exact_greedy.h"

namespace cf::detail {

// Pending sources (active, not exact, bound < best, own group radius >= radius) of the seed's
// family connected to it by mesh edges within `radius` mm along the tree grown breadth-first
// from it, none marked `taken` or later (the other groups of this batch). Returns member slots, seed first,
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
      if (group_mark_[w] == group_stamp_ || (taken != 0 && group_mark_[w] >= taken)) continue;
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

// One search from the group around `seed` (best = the best known loop's value) and a batch of
// further groups from the next seeds of the far-first order (or far in space from the seed),
// split over the threads. Any order of searches keeps the
// result exact (every bound stays a valid lower bound); a group that an earlier one of its
// batch would have certified costs one search more.
void ExactGreedy::search_group(int seed, double best) {
  Stopwatch sw;
  std::vector<GroupRun> runs{prepare_group(seed, best, 0)};
  const std::uint32_t first = group_stamp_;  // the batch's groups have marks >= first
  for (std::size_t want = batch_size(); runs.size() < want;) {
    const int other = next_seed(runs, best, first);
    if (other < 0) break;
    runs.push_back(prepare_group(other, best, first));
  }
  for (const auto& entry : far_skipped_) {  // back into the far-first order
    far_order_.push_back(entry);
    std::push_heap(far_order_.begin(), far_order_.end());
  }
  far_skipped_.clear();
  const bool taken = runs.size() == 1 && take_speculation(runs[0]);
  spec_ready_ = false;
  if (taken) settled_alone_ += static_cast<long long>(runs[0].settled);  // searched alone, ahead
  else if (runs.size() == 1 && can_speculate()) run_alone_with_guess(runs[0], best);
  else run_groups(runs);
  mixed_batches_ += std::any_of(runs.begin(), runs.end(),
                                [&](const GroupRun& g) { return slots_[g.seed].family != slots_[seed].family; });
  std::size_t settled = 0;
  for (const GroupRun& g : runs) {
    settled += g.settled;
    finish_group(g, best);
  }
  last_group_settled_ = settled / runs.size();
  st_.t.search += sw.seconds();
}

// Groups in the next batch: 1 while the Z family is being found (its first loop comes from run
// 0's search state); else enough for kBatchWork settled vertices per lane, kBatchLanes lanes.
// Never from the thread count: the batches, hence every search and bound, are the same whatever
// the number of threads that runs them (identical loops and mesh for any --threads).
std::size_t ExactGreedy::batch_size() const {
  if (crossing_ && families_.size() == 2) return 1;
  const std::size_t per_lane = kBatchWork / std::max<std::size_t>(1, last_group_settled_);
  return kBatchLanes * std::clamp<std::size_t>(per_lane, 1, kMaxBatch);
}

// Whether a group search from `seed` may settle a vertex that the search of g settles (their
// balls, within limit/2 of the group's roots, can meet: Euclidean test, which bounds the graph
// distance from below). Groups of a batch are kept apart so that none certifies another.
// Searches of different families never do (each raises only its own family's bounds): A's and
// Z's groups of the crossing families pair whatever their distance.
bool ExactGreedy::near_group(int seed, const GroupRun& g) const {
  if (slots_[seed].family != slots_[g.seed].family) return false;
  const double reach = g.radius + g.limit;  // both balls: roots within the radius, searched to limit/2
  const Vec3& a = st_.mesh.point(Mesh::VertexHandle(slots_[seed].vertex));
  const Vec3& b = st_.mesh.point(Mesh::VertexHandle(slots_[g.seed].vertex));
  return (a - b).sqrnorm() < reach * reach;
}

// The next seed of a batch: the next farthest pending source outside the batch's groups
// (marked since `taken`) and away from them (the near ones go to far_skipped_ and back into
// the far-first order after the batch), else the pending source of the first seed's family
// farthest in space from it and away from the batch, or -1.
int ExactGreedy::next_seed(const std::vector<GroupRun>& batch, double best, std::uint32_t taken) {
  auto away = [&](int s) {
    return std::none_of(batch.begin(), batch.end(), [&](const GroupRun& g) { return near_group(s, g); });
  };
  for (int s = farthest_pending(best); s >= 0; s = farthest_pending(best)) {
    if (group_mark_[slots_[s].vertex] >= taken) continue;
    if (away(s)) return s;
    far_skipped_.push_back({far_popped_distance_, s});
    if (far_skipped_.size() >= kMaxSkipped) return -1;
  }
  const int seed = batch.front().seed;
  const Vec3& from = st_.mesh.point(Mesh::VertexHandle(slots_[seed].vertex));
  int other = -1;
  double farthest = -1;
  for (int s : active_) {
    const Slot& slot = slots_[s];
    if (!slot.active || slot.bound.exact || !(slot.bound.value < best) || slot.family != slots_[seed].family) continue;
    if (group_mark_[slot.vertex] >= taken) continue;
    const double d = (st_.mesh.point(Mesh::VertexHandle(slot.vertex)) - from).sqrnorm();
    if (d > farthest && away(s)) farthest = d, other = s;
  }
  return other;
}

// Searches one group and keeps what finish_group() needs (reads the greedy's state only, so two
// threads may run it at once with their own search objects).
void ExactGreedy::run_group(GroupRun& g, FundamentalCycleSearch& search) const {
  const Family& fam = families_[slots_[g.seed].family];
  search.set_cochain(fam.cochain.empty() ? nullptr : &fam.cochain);
  g.result = search.run_group(g.roots, g.root_parent, g.limit);
  g.settled = search.last_settled();
  for (int t : search.last_settled_vertices())
    if (t < static_cast<int>(fam.slot_of.size()) && fam.slot_of[t] >= 0) {
      g.ball.push_back(t);
      g.ball_distance.push_back(search.distance(t));
    }
  if (g.result.found) {
    g.root_u = search.root_of(g.result.u.idx());
    g.root_v = search.root_of(g.result.v.idx());
  }
}

// Run 0 on this thread's search object (extract() of its result stays possible); with T
// threads, each thread takes the next run not yet taken (run 0 first on this thread) with its
// own search object, so that a lane that drew a small group goes on with the next one instead
// of idling beside a large one. A run's result does not depend on the search object or thread
// that computes it, so the batch's results are the same for any thread count.
void ExactGreedy::run_groups(std::vector<GroupRun>& runs) {
  const int lanes = search_lanes(runs.size());
  if (runs.size() == 1) {  // alone on this thread whatever the thread count
    run_group(runs[0], *search_);
    settled_alone_ += static_cast<long long>(runs[0].settled);
    return;
  }
  if (lanes == 1) {
    for (GroupRun& g : runs) run_group(g, *search_);
    return;
  }
  parallel_pairs_ += static_cast<long long>(runs.size() / 2);
  std::atomic<std::size_t> next{1};
  std::vector<long long> lane_settled(lanes, 0);
  worker_->run(lanes, [&](int t) {
    for (std::size_t i = t == 0 ? 0 : next++; i < runs.size(); i = next++) {
      run_group(runs[i], lane_search(t));
      lane_settled[t] += static_cast<long long>(runs[i].settled);
    }
  });
  settled_longest_lane_ += *std::max_element(lane_settled.begin(), lane_settled.end());
}

int ExactGreedy::search_lanes(std::size_t tasks) {
  const int lanes = worker_ ? static_cast<int>(std::min<std::size_t>(worker_->threads(), tasks)) : 1;
  while (static_cast<int>(searches_extra_.size()) + 1 < lanes) {
    searches_extra_.push_back(std::make_unique<FundamentalCycleSearch>(st_.mesh, homology_, span_));
    searches_extra_.back()->set_adjacency(&adjacency_);
  }
  return lanes;
}

// Bounds after a group search of value `own`: F >= own for every member, F >= own - 2d for
// the family's sources settled at distance d from the group, F = own for the root both tree
// paths of the cycle lead to (a real closed walk through it). Members still below `best` are
// searched next in groups of half the radius (down to single searches).
void ExactGreedy::finish_group(const GroupRun& g, double best) {
  const CycleCandidate& c = g.result;
  ++searches_;
  group_searches_ += g.members.size() > 1;
  group_members_ += g.members.size() > 1 ? static_cast<long long>(g.members.size()) : 0;
  settled_ += static_cast<long long>(g.settled);
  largest_limit_ = std::max(largest_limit_, g.limit);
  slots_[g.seed].own_limit = g.limit;
  const double own = c.found ? c.value : c.truncated ? g.limit : kInf;
  spread_bounds(g.seed, own, g.ball, g.ball_distance);
  if (slots_[g.seed].bound.value < own) set_bound(g.seed, SourceBound{own, false, slots_[g.seed].vertex, 0});
  const std::vector<int>& slot_of = families_[slots_[g.seed].family].slot_of;
  if (c.found) {
    const int root = g.root_u;
    if (root == g.root_v && root < static_cast<int>(slot_of.size()) && slot_of[root] >= 0 &&
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
