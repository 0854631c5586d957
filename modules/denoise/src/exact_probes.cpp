// Paired searches of the exact method while no loop is known (exact_greedy.h). Before the first
// loop of a round is found, each step searched the one source at the top of the queue to twice
// its bound, alone: on the real CT surface's last handles most of the settled vertices (cut 89:
// 4.8 of 5.9 M), with the second core idle. Any order of searches keeps the result exact (every
// bound stays a valid lower bound, and only an exact entry at the top of the queue is cut), so a
// second source may be searched beside the first. It is taken from the queue, never from the
// thread count, so the searches are the same for any --threads.
#include <algorithm>
#include <cmath>
#include <vector>

#include "colonflat/core/run_stats.h"
#include "exact_greedy.h"

namespace cf::detail {

// Searches `first` (the top of the queue) and, when there is one, its partner; with two
// threads at once. The results are applied in that order.
void ExactGreedy::probe(int first) {
  const double limit = search_limit(first);
  const int partner = probe_partner(first, limit);
  if (partner < 0) {
    search_from(first, limit);
    return;
  }
  Stopwatch sw;
  std::vector<ProbeRun> runs(2);
  runs[0].slot = first;
  runs[0].limit = limit;
  runs[1].slot = partner;
  runs[1].limit = search_limit(partner);
  ++probe_pairs_;
  if (search_lanes(2) > 1) {
    worker_->run(2, [&](int t) { run_probe(runs[t], lane_search(t)); });
    ++parallel_pairs_;
    settled_longest_lane_ += static_cast<long long>(std::max(runs[0].settled, runs[1].settled));
  } else {
    for (ProbeRun& p : runs) run_probe(p, *search_);
  }
  for (const ProbeRun& p : runs) finish_probe(p);
  st_.t.search += sw.seconds();
}

// The first pending entry of the queue (lowest bound first, at most kMaxPartnerScan looked at)
// whose source lies farther from first's, in space, than the two searches' radii together
// (limit / 2 each; the Euclidean distance bounds the graph distance from below): neither search
// then settles the other's source, so the first's bounds cannot have made the partner's search
// unneeded. -1 if none. The entries looked at go back into the queue (stale ones are dropped, as
// run() drops them).
int ExactGreedy::probe_partner(int first, double limit) {
  const Vec3& from = st_.mesh.point(Mesh::VertexHandle(slots_[first].vertex));
  std::vector<QueueEntry> looked;
  int partner = -1;
  while (!queue_.empty() && looked.size() < kMaxPartnerScan) {
    const QueueEntry e = queue_.top();
    queue_.pop();
    const Slot& slot = slots_[e.slot];
    if (!slot.active || e.version != slot.bound.version) continue;
    looked.push_back(e);
    if (e.exact || e.slot == first) continue;
    if (e.key >= opts_.max_loop_length) break;
    const double reach = 0.5 * (limit + search_limit(e.slot));
    if ((st_.mesh.point(Mesh::VertexHandle(slot.vertex)) - from).sqrnorm() > reach * reach) {
      partner = e.slot;
      break;
    }
  }
  for (const QueueEntry& e : looked) queue_.push(e);
  return partner;
}

// One search of a pair, keeping what finish_probe() needs (reads the greedy's state only).
void ExactGreedy::run_probe(ProbeRun& p, FundamentalCycleSearch& search) const {
  const int family = slots_[p.slot].family;
  search.set_cochain(family == 0 ? nullptr : &families_[family].cochain);
  p.result = search.run(Mesh::VertexHandle(slots_[p.slot].vertex), p.limit, nullptr);
  p.settled = search.last_settled();
  p.ball = search.last_settled_vertices();
  p.ball_distance.resize(p.ball.size());
  for (std::size_t i = 0; i < p.ball.size(); ++i) p.ball_distance[i] = search.distance(p.ball[i]);
}

// What search_from() does with its result: the source's bound (exact when a cycle was found),
// and the bounds it implies for the family's sources it settled.
void ExactGreedy::finish_probe(const ProbeRun& p) {
  const CycleCandidate& c = p.result;
  ++searches_;
  settled_ += static_cast<long long>(p.settled);
  largest_limit_ = std::max(largest_limit_, p.limit);
  slots_[p.slot].own_limit = p.limit;
  const double own = c.found ? c.value : c.truncated ? p.limit : kInf;
  set_bound(p.slot, SourceBound{own, c.found, slots_[p.slot].vertex, 0});
  spread_bounds(p.slot, own, p.ball, p.ball_distance);
}

}  // namespace cf::detail
