#pragma once
// The shortest loop crossing a given loop an odd number of times, among the fundamental cycles
// from a spread of the loop's vertices (the exact method's fallback, exact_fallback.cpp): found by
// certifying stretches of the loop with multi-root searches and searching only the sources they
// cannot certify, instead of every source to the best value (crossing_search.cpp).
#include <cstdint>
#include <functional>
#include <vector>

#include "colonflat/denoise/loop_search.h"

namespace cf {

struct CrossingLoopInput {
  const Mesh* mesh = nullptr;
  const std::vector<Mesh::VertexHandle>* loop = nullptr;  // simple loop of interior vertices
  const std::vector<std::uint8_t>* cochain = nullptr;      // crossing_cochain(*mesh, *loop)
  double limit = 0;              // mm: loops of this value or more are not returned
  std::size_t max_sources = 24;  // sources: every (loop size / max_sources)-th loop vertex
  std::size_t batch = 2;         // searches per batch, each to the best value before it: a fixed
                                 // number, so that the searches are the same for any lane count
  int lanes = 1;                 // searches run side by side, one per lane
  std::function<FundamentalCycleSearch&(int)> lane_search;  // lane t's search object, t < lanes
  // Runs job(t) for t in [0, n), n <= lanes, and returns when all are done (null: lanes == 1).
  std::function<void(int n, const std::function<void(int)>& job)> run_lanes;
};

// The picked positions of n candidate sources: 0, k, 2k, ... below n with k = max(1, n / max_picks)
// (the exact fallback's spread: shortest_crossing_loop and ExactGreedy::shortest_from_spread).
std::vector<std::size_t> spread_positions(std::size_t n, std::size_t max_picks);

struct CrossingSearchCount {
  long long searches = 0, groups = 0, settled = 0;
};

// The loop that searching every picked source on its own, in order, each to the best value found
// before it, returns: the shortest fundamental cycle value, among equal values the first source's
// (empty when none is below the limit); the same loop and searches for any number of lanes.
// Adds its searches to *count.
std::vector<Mesh::VertexHandle> shortest_crossing_loop(const CrossingLoopInput& in, CrossingSearchCount* count);

}  // namespace cf
