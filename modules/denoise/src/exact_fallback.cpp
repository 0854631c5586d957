// The exact method's fallback for loops that cannot be capped cleanly (exact_greedy.h): the
// surgery is undone and another loop that removes the same handle is cut instead (one of the
// same class away from the first, or one crossing it).
#include <algorithm>

#include "colonflat/core/error.h"
#include "colonflat/core/geodesic_ball.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/denoise/crossing_search.h"
#include "exact_greedy.h"

namespace cf::detail {

// Cuts `loop`; when every placement of its caps intersects the surface (with --check-caps), the
// surgery is undone and other loops that remove the same handle are tried as trials (kept only
// when their caps are clean, so their concentric caps are not searched for the placement with
// the fewest pairs); the first one capped cleanly is kept and records the loop it replaces:
//  1. the shortest loop of the same class (modulo the classes cut before) outside a tube
//     around `loop`, for tube radii of kNearTubeEdges mean edges (a loop on one face of a thin
//     wall beside the rim `loop` runs along), then delta and 2 delta;
//  2. the shortest loop crossing `loop` an odd number of times: the handle's other loop, whose
//     disk is the handle's other disk (where no disk of `loop`'s class avoids the surface, e.g.
//     something runs through the tube, the other may: it spans the hole). Plain triangulations
//     only: on the real CT surface the restricted ones took 7-14 s (wall, loaded machine) on
//     such loops (235-242 vertices) and never found clean caps.
// If none is, `loop` is cut again (concentric caps only: its triangulated caps failed in its first
// cut on this same mesh) and its intersections are reported as before. Precondition:
// `reduced` = loop's class reduced modulo the span (nonzero). *cut_class receives the class of
// the loop actually cut, *cut_loop (optional) the loop. Throws when a cut separates.
SurgeryResult ExactGreedy::cut_cleanly(const std::vector<Mesh::VertexHandle>& loop,
                                       const std::vector<std::uint64_t>& reduced, int iteration,
                                       std::vector<std::uint64_t>* cut_class,
                                       std::vector<Mesh::VertexHandle>* cut_loop) {
  if (cut_loop) *cut_loop = loop;
  SurgeryResult sr = cut_recorded(loop, iteration, CapAttempt::kFirst);
  if (sr.intersections == 0 || !opts_.check_caps) return sr;
  const double length = st_.loops.back().length;
  const std::size_t intersections = sr.intersections;
  const double delta = std::max(5.0 * st_.mean_edge, length / 8.0);
  auto clean = [&](const std::vector<Mesh::VertexHandle>& other, CapAttempt attempt, int* counter) {
    if (shortcut_guard_ && !keeps_shortcut(other)) return false;
    sr = cut_recorded(other, iteration, attempt);
    if (sr.intersections > 0) {
      revert_cut(sr);
      return false;
    }
    st_.loops.back().replaced_length = length;
    st_.loops.back().replaced_intersections = intersections;
    if (cut_loop) *cut_loop = other;
    ++*counter;
    return true;
  };
  revert_cut(sr);
  const double edge = st_.mean_edge;
  for (double tube : {kNearTubeEdges[0] * edge, kNearTubeEdges[1] * edge, delta, 2.0 * delta}) {
    const std::vector<Mesh::VertexHandle> other = same_class_loop(loop, reduced, tube);
    if (other.empty() && tube >= delta) break;
    if (!other.empty() && clean(other, CapAttempt::kTrial, &alternatives_)) return sr;
  }
  const std::vector<Mesh::VertexHandle> dual = crossing_loop(loop, 3.0 * length + 4.0 * delta);
  if (!dual.empty()) {
    std::vector<std::uint64_t> cls = search_->cycle_class(dual);
    if (clean(dual, CapAttempt::kPlainTrial, &crossing_alternatives_)) {
      *cut_class = std::move(cls);
      return sr;
    }
  }
  // The first cut ended with pairs, so its triangulated caps all failed (they are only kept clean),
  // and the trials were undone: the mesh is as it was, and the same steps would fail again.
  return cut_recorded(loop, iteration, CapAttempt::kAgain);
}

// Records and cuts one loop; throws when the two sides of the cut are no longer connected.
SurgeryResult ExactGreedy::cut_recorded(const std::vector<Mesh::VertexHandle>& loop, int iteration,
                                        CapAttempt attempt) {
  const int comp = st_.component[loop.front().idx()];
  st_.record(loop, iteration, false);
  SurgeryResult sr;
  const bool connected = cut_loop(st_, loop, opts_, &homology_, &sr, attempt);
  adjacency_.refresh(st_.mesh, touched_by_surgery(st_.mesh, sr.undo));
  if (!connected)
    throw Error("denoise: surgery along loop " + std::to_string(iteration - 1) + " (length " +
                format_number(st_.loops.back().length) + " mm) split component " + std::to_string(comp) +
                " - the loop was separating; refusing to continue");
  return sr;
}

// Undoes the last cut_recorded() (mesh, bookkeeping; the guard forgets the faces it added: a
// rebuild of the whole grid cost 0.2-0.4 s per undo at 1.8 M faces).
void ExactGreedy::revert_cut(const SurgeryResult& sr) {
  Stopwatch sw;
  const std::vector<int> touched = touched_by_surgery(st_.mesh, sr.undo);  // on the mesh with the cut
  undo_surgery(st_.mesh, sr.undo);
  adjacency_.refresh(st_.mesh, touched);
  if (st_.guard) st_.guard->forget_faces_from(static_cast<int>(sr.undo.faces));
  st_.cap_rings.resize(st_.cap_rings.size() - 2);
  st_.origin.resize(st_.mesh.n_vertices());
  st_.component.resize(st_.mesh.n_vertices());
  st_.loops.pop_back();
  st_.t.surgery += sw.seconds();
}

// The shortest loop crossing `loop` an odd number of times (crossing_cochain(): any such cycle
// is non-separating and not of loop's class), among fundamental cycles from up to
// kFallbackSources of loop's vertices (every such cycle passes through one of them); empty when
// none is found within `limit`. The same loop as shortest_from_spread() over those sources, with
// stretches of the loop certified by group searches (crossing_search.h).
std::vector<Mesh::VertexHandle> ExactGreedy::crossing_loop(const std::vector<Mesh::VertexHandle>& loop, double limit) {
  Stopwatch sw;
  const std::vector<std::uint8_t> cochain = crossing_cochain(st_.mesh, loop);
  CrossingLoopInput in;
  in.mesh = &st_.mesh;
  in.loop = &loop;
  in.cochain = &cochain;
  in.limit = limit;
  in.max_sources = kFallbackSources;
  in.batch = kBatchLanes;
  in.lanes = search_lanes(kBatchLanes);
  in.lane_search = [this](int t) -> FundamentalCycleSearch& { return lane_search(t); };
  if (worker_) in.run_lanes = [this](int n, const std::function<void(int)>& job) { worker_->run(n, job); };
  CrossingSearchCount count;
  const std::vector<Mesh::VertexHandle> found = shortest_crossing_loop(in, &count);
  searches_ += count.searches;
  settled_ += count.settled;
  fallback_settled_ += count.settled;
  st_.t.search += sw.seconds();
  fallback_s_ += sw.seconds();
  return found;
}

// The shortest loop whose class equals `reduced` modulo the span, avoiding every vertex closer
// than `tube` to `loop`, among fundamental cycles from up to kFallbackSources vertices spread
// over the tube's rim (a loop of that class parallel to `loop` passes near the rim). Empty when
// none is found within three times the loop's length.
std::vector<Mesh::VertexHandle> ExactGreedy::same_class_loop(const std::vector<Mesh::VertexHandle>& loop,
                                                             const std::vector<std::uint64_t>& reduced, double tube) {
  Stopwatch sw;
  std::vector<double> dist;
  const std::vector<int> near = vertices_within(st_.mesh, loop, tube + 3.0 * st_.mean_edge, &dist);
  std::vector<std::uint8_t> avoid(st_.mesh.n_vertices(), 0);
  std::vector<int> rim;
  for (std::size_t i = 0; i < near.size(); ++i) (dist[i] < tube ? avoid[near[i]] = 1 : (rim.push_back(near[i]), 0));
  FundamentalCycleSearch::Accept same_class = [&](const std::vector<Mesh::VertexHandle>& cycle) {
    std::vector<std::uint64_t> cls = search_->cycle_class(cycle);
    span_.reduce(cls.data());
    return cls == reduced;
  };
  std::vector<Mesh::VertexHandle> sources;
  for (int v : rim) sources.push_back(Mesh::VertexHandle(v));
  const std::vector<Mesh::VertexHandle> found =
      shortest_from_spread(sources, 3.0 * loop_length(st_.mesh, loop) + 4.0 * tube, &same_class, nullptr, &avoid);
  st_.t.search += sw.seconds();
  fallback_s_ += sw.seconds();
  return found;
}

// The shortest fundamental cycle of value below `limit` (with `cochain`: crossing it oddly,
// else of a class outside the span; approved by `accept` when given; never entering `avoid`)
// from up to `max_sources` of `sources`, spread evenly; empty if none. The sources are
// searched kBatchLanes at a time, each to the best value known before its batch, on the
// worker's threads; the results are then taken in source order, a strictly shorter one
// replacing the best. A search to a higher limit finds the same shortest cycle through its
// source when one lies below the lower limit, so the loop found is the one searching the
// sources one after the other finds, for any thread count.
std::vector<Mesh::VertexHandle> ExactGreedy::shortest_from_spread(const std::vector<Mesh::VertexHandle>& sources,
                                                                  double limit,
                                                                  const FundamentalCycleSearch::Accept* accept,
                                                                  const std::vector<std::uint8_t>* cochain,
                                                                  const std::vector<std::uint8_t>* avoid,
                                                                  std::size_t max_sources) {
  std::vector<Mesh::VertexHandle> picked;
  for (std::size_t i : spread_positions(sources.size(), max_sources)) picked.push_back(sources[i]);
  const int lanes = search_lanes(kBatchLanes);
  double best = limit;
  std::vector<Mesh::VertexHandle> found;
  for (std::size_t b = 0; b < picked.size(); b += kBatchLanes) {
    const std::size_t n = std::min(kBatchLanes, picked.size() - b);
    std::vector<CycleCandidate> result(n);
    std::vector<std::vector<Mesh::VertexHandle>> cycle(n);
    std::vector<std::size_t> settled(n);
    auto lane = [&](int t) {
      FundamentalCycleSearch& search = lane_search(t);
      search.set_cochain(cochain);
      search.set_avoid(avoid);
      for (std::size_t j = t; j < n; j += lanes) {
        result[j] = search.run(picked[b + j], best, accept);
        settled[j] = search.last_settled();
        if (result[j].found && result[j].value < best) cycle[j] = search.extract(result[j]);
      }
      search.set_cochain(nullptr);
      search.set_avoid(nullptr);
    };
    if (lanes > 1) worker_->run(lanes, lane);
    else lane(0);
    for (std::size_t j = 0; j < n; ++j) {
      ++searches_;
      settled_ += static_cast<long long>(settled[j]);
      fallback_settled_ += static_cast<long long>(settled[j]);
      if (result[j].found && result[j].value < best) {
        best = result[j].value;
        found = std::move(cycle[j]);
      }
    }
  }
  return found;
}

}  // namespace cf::detail
