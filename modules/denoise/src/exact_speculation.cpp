// Group searches ahead (exact_greedy.h): in the last cuts of a colon the pending sources all lie
// within the reach of near_group(), so every batch holds one group and the helper thread idles
// (real CT: 4.2 M of cuts 91-93's 5 M settled vertices). The group the next batch will most
// likely form is searched beside it and kept; the next batch takes its result only if it forms
// that very group, so the searches, bounds and loops are those of the batches alone.
#include <algorithm>

#include "exact_greedy.h"

namespace cf::detail {

// With a helper thread, and not while Z's family is found (that search's state is used after it).
bool ExactGreedy::can_speculate() const {
  return worker_ && worker_->threads() > 1 && !(crossing_ && families_.size() == 2);
}

// The next pending source of the far-first order (up to kMaxSkipped entries ahead) outside `alone`,
// with its group as it stands now; seed -1 if none. (Taking only sources that the search of
// `alone` cannot certify, Euclidean test, was taken 10 times in 45 on the real CT surface; this,
// 65 in 137: the next seed is most often a neighbour that the search could have certified and
// did not.)
ExactGreedy::GroupRun ExactGreedy::guess_next_group(const GroupRun& alone, double best) {
  std::vector<std::pair<double, int>> order = far_order_;  // a copy of the max-heap
  for (std::size_t k = 0; k < kMaxSkipped && !order.empty(); ++k) {
    std::pop_heap(order.begin(), order.end());
    const int s = order.back().second;
    order.pop_back();
    const Slot& slot = slots_[s];
    if (!slot.active || slot.bound.exact || !(slot.bound.value < best)) continue;
    if (std::find(alone.members.begin(), alone.members.end(), s) != alone.members.end()) continue;
    return prepare_group(s, best, 0);
  }
  return GroupRun{};
}

// Searches `alone` here and the guessed next group on the helper thread.
void ExactGreedy::run_alone_with_guess(GroupRun& alone, double best) {
  GroupRun guess = guess_next_group(alone, best);
  if (guess.seed < 0) {
    run_group(alone, *search_);
    settled_alone_ += static_cast<long long>(alone.settled);
    return;
  }
  search_lanes(2);
  worker_->run(2, [&](int t) { t == 0 ? run_group(alone, *search_) : run_group(guess, lane_search(1)); });
  settled_alone_ += static_cast<long long>(alone.settled);
  spec_ = std::move(guess);
  spec_ready_ = true;
  ++spec_runs_;
}

// The group searched ahead in place of g's search, if it is g (a search's result depends only on
// its roots, tree edges and limit, the family and the mesh, none of which changed since).
bool ExactGreedy::take_speculation(GroupRun& g) {
  if (!spec_ready_ || spec_.seed != g.seed || spec_.radius != g.radius || spec_.limit != g.limit ||
      spec_.members != g.members || spec_.root_parent != g.root_parent)
    return false;
  g = std::move(spec_);
  ++spec_hits_;
  return true;
}

}  // namespace cf::detail
