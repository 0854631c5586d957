// Triangulated caps of both rings in one placement (step 7a of the Surgery, surgery_steps.h): the
// minimum-area triangulations, restricted to clean triangles with a guard, right ring first, then
// the mirror, then the left ring avoiding the right cap, then the other way round (left_first).
// With a helper thread (SurgeryOptions::run_both) left_first()'s first triangulation is made on it
// beside the right ring's. Tests: surgery_caps_test.cpp.
#include <unordered_map>

#include "colonflat/denoise/cap_triangulation.h"
#include "colonflat/denoise/face_grid.h"
#include "surgery_steps.h"

namespace cf::detail {

// Minimum-area triangulations of both rings (with `avoid`: only triangles that intersect nothing);
// true when both exist and together intersect nothing. With `avoid` and a helper thread, the left
// ring's triangulation avoiding the surface only (left_first()'s first step, needed when the
// left ring has no cap avoiding the right one) is made on the helper meanwhile, and called off as
// soon as the calling thread knows it is not needed.
bool Surgery::triangulate_both(bool avoid, std::vector<std::array<int, 3>>* right, std::vector<std::array<int, 3>>* left) {
  right_cache_ = {};  // the rings have moved: answers of the last placement do not hold
  left_cache_ = {};
  LeftAhead ahead;
  bool mirrored = false;
  auto mine = [&] {
    mirrored = right_then_left(avoid, right, left);
    if (right->empty() || mirrored || !left->empty()) ahead.cancel = true;  // left_first() will not be called
  };
  if (avoid && opts_.run_both) {
    const long long budget = query_budget_;  // the most left_first() can have left (budgets only fall)
    opts_.run_both(mine, [&] { left_ahead(budget, &ahead); });
  } else {
    mine();
  }
  // Fail fast: the placements move the ring by fractions of an edge; a right ring with no clean
  // triangulation in one placement had none in any other on the real CT surface (issue 26).
  if (right->empty()) {
    gave_up_ = gave_up_ || avoid;  // also when the budget ran out
    return false;
  }
  if (mirrored) return true;
  if (avoid && left->empty()) left_first(ahead, right, left);
  gave_up_ = gave_up_ || query_budget_ <= 0;
  if (left->empty()) return false;
  std::vector<std::array<int, 3>> all = *right;
  all.insert(all.end(), left->begin(), left->end());
  return opts_.guard->count_triangles(mesh_, all) == 0;
}

// The right ring's triangulation, then (with `avoid`) the mirror of it, else the left ring's
// avoiding it; true when the mirror is kept. Reads the mesh and the grid only (a helper thread
// may read them meanwhile).
bool Surgery::right_then_left(bool avoid, std::vector<std::array<int, 3>>* right, std::vector<std::array<int, 3>>* left) {
  // A diagonal that is already a mesh edge (a chord on that side) would make the cap non-manifold.
  auto chord = [&](Mesh::VertexHandle a, Mesh::VertexHandle b) { return mesh_.find_halfedge(a, b).is_valid(); };
  const FaceGrid* grid = avoid ? opts_.guard : nullptr;
  *right = triangulate_ring(mesh_, result_.right_ring, chord, grid, {}, &query_budget_, avoid ? &right_cache_ : nullptr);
  if (right->empty()) return false;
  if (avoid && mirror_cap(*right, left)) return true;
  *left = triangulate_ring(mesh_, left_cap_order(result_.left_ring), chord, grid, *right, &query_budget_,
                           avoid ? &left_cache_ : nullptr);
  return false;
}

// On the helper thread: the left ring's restricted triangulation avoiding the surface only, within
// `budget` grid queries (no cache: left_cache_ is the calling thread's meanwhile, and a cache
// changes no answer). ahead->queries stays -1 when it was called off.
void Surgery::left_ahead(long long budget, LeftAhead* ahead) const {
  auto chord = [&](Mesh::VertexHandle a, Mesh::VertexHandle b) { return mesh_.find_halfedge(a, b).is_valid(); };
  const long long before = budget;
  ahead->tris = triangulate_ring(mesh_, left_cap_order(result_.left_ring), chord, opts_.guard, {}, &budget, nullptr,
                                 &ahead->cancel);
  if (!ahead->cancel) ahead->queries = before - budget;
}

// The restricted triangulations the other way round, after the right ring's was found and the left
// ring's (avoiding it) was not: the left ring's first, avoiding the surface only, then the right
// ring's avoiding it. The two rings are a fraction of an edge apart, so the two caps compete for
// the same clean passage, and the first minimum-area cap takes the side of it that leaves the
// other none where the other order leaves room for both (issue 26, session 20: on the real CT
// surface the 114-, 96- and 178-vertex loops, whose right-first caps fail in 5-7 placements).
// Both reuse the grid answers of triangulate_both's calls for the same rings (RingQueryCache: the
// same result as without it). The left ring's is taken from `ahead` (made on the helper thread)
// when it ran to its end within the budget left now: the triangulation made here would ask the
// same triangles in the same rounds (the answers are pure, a cached one counts as its query) and,
// never above the budget, end with the same triangles and query count. On success *right and
// *left are replaced; otherwise *left stays empty.
bool Surgery::left_first(const LeftAhead& ahead, std::vector<std::array<int, 3>>* right,
                         std::vector<std::array<int, 3>>* left) {
  auto chord = [&](Mesh::VertexHandle a, Mesh::VertexHandle b) { return mesh_.find_halfedge(a, b).is_valid(); };
  std::vector<std::array<int, 3>> l;
  if (ahead.queries >= 0 && ahead.queries <= query_budget_) {
    l = ahead.tris;
    query_budget_ -= ahead.queries;
    ++result_.left_caps_ahead;
  } else {
    l = triangulate_ring(mesh_, left_cap_order(result_.left_ring), chord, opts_.guard, {}, &query_budget_, &left_cache_);
  }
  if (l.empty()) return false;
  std::vector<std::array<int, 3>> r =
      triangulate_ring(mesh_, result_.right_ring, chord, opts_.guard, l, &query_budget_, &right_cache_);
  if (r.empty()) return false;
  *right = std::move(r);
  *left = std::move(l);
  return true;
}

// The left cap as the right one's mirror: the same triangles on the left copies, reversed (the
// rings are a fraction of an edge apart, so the two caps are nearly parallel); kept when no
// diagonal is a mesh edge on the left side and both caps together intersect nothing. Restricting
// the left ring's own triangulation to avoid the right cap failed where the mirror is clean.
bool Surgery::mirror_cap(const std::vector<std::array<int, 3>>& right, std::vector<std::array<int, 3>>* left) {
  std::unordered_map<int, std::size_t> index;
  for (std::size_t i = 0; i < k_; ++i) index[result_.right_ring[i].idx()] = i;
  left->clear();
  for (const auto& t : right) {
    std::array<std::size_t, 3> r = {index.at(t[0]), index.at(t[2]), index.at(t[1])};
    for (int e = 0; e < 3; ++e) {
      const std::size_t a = r[e], b = r[(e + 1) % 3];
      const bool ring_edge = (a + 1) % k_ == b || (b + 1) % k_ == a;
      if (!ring_edge && mesh_.find_halfedge(result_.left_ring[a], result_.left_ring[b]).is_valid()) return false;
    }
    left->push_back({result_.left_ring[r[0]].idx(), result_.left_ring[r[1]].idx(), result_.left_ring[r[2]].idx()});
  }
  std::vector<std::array<int, 3>> all = right;
  all.insert(all.end(), left->begin(), left->end());
  return opts_.guard->count_triangles(mesh_, all) == 0;
}
}  // namespace cf::detail
