// The exact fallback's crossing loop (exact_fallback.cpp) found with fewer settled vertices: the loop's
// sources are certified in runs by multi-root searches (run_group along the loop) and only the
// sources a run cannot certify are searched one by one. The loop returned is the one searching
// every picked source on its own returns (shortest_from_spread(): the shortest value, the first
// source in order among equal values), for any thread count.
//
// Why it is exact: the crossing family (odd sum of the loop's crossing cochain) satisfies the
// 3-path condition, so a source's own search gives F(s), the shortest crossing closed walk
// through s, and a group search along a stretch of the loop gives a value M <= F(t) for every
// vertex t of the stretch (none found within a limit: F(t) > limit). A source whose lower bound
// exceeds the best value found is never the shortest; every other source is searched on its
// own, with a limit no lower than its own value when it can win.
#include "colonflat/denoise/crossing_search.h"

#include <algorithm>

namespace cf {

namespace {

// A stretch of picked sources [first, last] (indices into the picked list) and a lower bound
// of F over its loop vertices. first == last: one source, searched on its own.
struct CrossingItem {
  std::size_t first = 0, last = 0;
  double lower = 0;
  bool single() const { return first == last; }
};

// Result of one item's search, taken from the lane's search object before it runs the next.
struct CrossingOutcome {
  CycleCandidate result;
  std::vector<Mesh::VertexHandle> cycle;  // singles: the extracted loop, when found
  int root = -1;                          // runs: the root whose tree holds the cycle's end u
  std::size_t settled = 0;
};

// Values within this relative margin of the best count as ties: a group's sums run over other
// paths than a source's own, so a tie may differ in the last bits.
constexpr double kTieMargin = 1e-9;

// The next batch: up to `lanes` items of the kind of the first (singles before runs; then the
// lowest bound, then the first source), none whose bound exceeds `cut`. Removes them from work.
std::vector<CrossingItem> take_batch(std::vector<CrossingItem>& work, double cut, std::size_t lanes) {
  work.erase(std::remove_if(work.begin(), work.end(), [&](const CrossingItem& w) { return w.lower > cut; }),
             work.end());
  std::sort(work.begin(), work.end(), [](const CrossingItem& a, const CrossingItem& b) {
    if (a.single() != b.single()) return a.single();
    return a.lower != b.lower ? a.lower < b.lower : a.first < b.first;
  });
  std::vector<CrossingItem> batch;
  for (std::size_t i = 0; i < work.size() && batch.size() < lanes; ++i)
    if (batch.empty() || work[i].single() == batch.front().single()) batch.push_back(work[i]);
  work.erase(std::remove_if(work.begin(), work.end(),
                            [&](const CrossingItem& w) {
                              for (const CrossingItem& b : batch)
                                if (b.first == w.first && b.last == w.last) return true;
                              return false;
                            }),
             work.end());
  return batch;
}

// A run whose group search found a cycle of value m (root: the loop position of the root holding
// its end) is split: the sources either side of the root are searched on their own, the stretches
// before and after them become runs; all with the bound m.
void split_run(const CrossingItem& run, const std::vector<int>& position, int root, double m,
               std::vector<CrossingItem>* work) {
  std::size_t s = run.first;
  while (s < run.last && position[s + 1] <= root) ++s;
  const std::size_t hi = std::min(run.last, s + 1);
  for (std::size_t i = s; i <= hi; ++i) work->push_back({i, i, m});
  if (s > run.first) work->push_back({run.first, s - 1, m});
  if (hi < run.last) work->push_back({hi + 1, run.last, m});
}

// Searches one item on `search` to `limit`: a single source with run(), a run with run_group()
// over the loop vertices from its first to its last source (tree: the loop's own edges).
void search_item(FundamentalCycleSearch& search, const Mesh& mesh, const std::vector<Mesh::VertexHandle>& loop,
                 const std::vector<int>& position, const CrossingItem& item, double limit, CrossingOutcome* out) {
  if (item.single()) {
    out->result = search.run(loop[position[item.first]], limit);
    if (out->result.found) out->cycle = search.extract(out->result);
  } else {
    std::vector<int> roots, parent;
    for (int p = position[item.first]; p <= position[item.last]; ++p) {
      roots.push_back(loop[p].idx());
      parent.push_back(roots.size() == 1 ? -1 : mesh.find_halfedge(loop[p - 1], loop[p]).idx());
    }
    out->result = search.run_group(roots, parent, limit);
    if (out->result.found) {
      const int r = search.root_of(out->result.u.idx());
      for (int p = position[item.first]; p <= position[item.last]; ++p)
        if (loop[p].idx() == r) out->root = p;
    }
  }
  out->settled = search.last_settled();
}

// Runs one batch of items on the lanes, each to `limit`; outcome j belongs to batch[j].
std::vector<CrossingOutcome> run_batch(const CrossingLoopInput& in, const std::vector<int>& position,
                                       const std::vector<CrossingItem>& batch, double limit) {
  std::vector<CrossingOutcome> out(batch.size());
  const int lanes = std::min(in.lanes, static_cast<int>(batch.size()));
  auto lane = [&](int t) {
    FundamentalCycleSearch& search = in.lane_search(t);
    search.set_cochain(in.cochain);
    for (std::size_t j = t; j < batch.size(); j += lanes)
      search_item(search, *in.mesh, *in.loop, position, batch[j], limit, &out[j]);
    search.set_cochain(nullptr);
  };
  if (lanes > 1) in.run_lanes(lanes, lane);
  else lane(0);
  return out;
}

}  // namespace

std::vector<std::size_t> spread_positions(std::size_t n, std::size_t max_picks) {
  std::vector<std::size_t> picked;
  const std::size_t stride = std::max<std::size_t>(1, n / std::max<std::size_t>(1, max_picks));
  for (std::size_t i = 0; i < n; i += stride) picked.push_back(i);
  return picked;
}

std::vector<Mesh::VertexHandle> shortest_crossing_loop(const CrossingLoopInput& in, CrossingSearchCount* count) {
  std::vector<Mesh::VertexHandle> found;
  if (in.loop->empty()) return found;
  std::vector<int> position;  // loop position of each picked source
  for (std::size_t i : spread_positions(in.loop->size(), in.max_sources)) position.push_back(static_cast<int>(i));
  std::vector<CrossingItem> work{{0, position.size() - 1, 0.0}};
  double best = in.limit;
  std::size_t best_source = position.size();  // none yet: a value must then be below the limit
  for (;;) {
    const double cut = best * (1 + kTieMargin);
    const std::vector<CrossingItem> batch = take_batch(work, cut, std::max<std::size_t>(1, in.batch));
    if (batch.empty()) break;
    std::vector<CrossingOutcome> out = run_batch(in, position, batch, cut);
    for (std::size_t j = 0; j < batch.size(); ++j) {
      ++count->searches;
      count->groups += batch[j].single() ? 0 : 1;
      count->settled += static_cast<long long>(out[j].settled);
      const CycleCandidate& c = out[j].result;
      if (!c.found) continue;  // single: F > cut; run: F > cut at every source of the run
      if (!batch[j].single()) {
        split_run(batch[j], position, out[j].root, c.value, &work);
      } else if (c.value < best || (c.value == best && best_source < position.size() && batch[j].first < best_source)) {
        best = c.value;
        best_source = batch[j].first;
        found = std::move(out[j].cycle);
      }
    }
  }
  return found;
}

}  // namespace cf
