#include "colonflat/denoise/cap_triangulation.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <limits>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "colonflat/core/error.h"
#include "colonflat/core/threads.h"
#include "denoise_debug.h"

namespace cf {

namespace {

constexpr double kNone = std::numeric_limits<double>::infinity();

// The minimum-area dynamic programme with `allowed` asked lazily (issue 26, session 19): solve
// with the triangles and sides known to be refused left out, ask `allowed` (and `side_ok`) only for
// the n - 2 triangles of that solution, leave out those refused, and solve again. Every value of a
// round is at most the restricted one (fewer triangles are left out), so a solution whose triangles
// all pass is the restricted optimum, with the same tie-break (smallest apex m among the lightest
// at each subproblem) and the same floating-point sums: the result is the eager programme's,
// which asked `allowed` for the candidates of every subproblem lightest first (k^2 / 2 queries at
// least) and sorted them. A refused side (a, b) leaves out every triangle on it: subproblem (a, b)
// gets no triangulation.
class LazyMinArea {
 public:
  LazyMinArea(const std::vector<Vec3>& ring, const std::function<bool(int, int, int)>& allowed,
              const std::function<bool(int, int)>& side_ok, const std::function<bool()>& give_up)
      : p_(ring), n_(static_cast<int>(ring.size())), allowed_(allowed), side_ok_(side_ok), give_up_(give_up),
        W_(std::size_t(n_) * n_, 0.0), arg_(std::size_t(n_) * n_, -1), dead_(side_ok ? std::size_t(n_) * n_ : 0, 0),
        marked_(allowed && !side_ok ? std::size_t(n_) * n_ : 0, -1), changed_(marked_.size(), -1),
        lightest_first_(static_cast<bool>(side_ok)) {}
  std::vector<std::array<int, 3>> run();

 private:
  std::size_t at(int i, int j) const { return std::size_t(i) * n_ + j; }
  double area(int i, int m, int j) const { return 0.5 * OpenMesh::cross(p_[m] - p_[i], p_[j] - p_[i]).norm(); }
  void solve(int i, int j);
  void solve_lightest_first(int i, int j);
  void lighter_than_refused(int i, int j, int refused, double* best, int* best_m);
  void solve_around(int i_hi, int j_lo);
  std::vector<std::array<int, 3>> extract() const;
  bool refuse_failing(const std::vector<std::array<int, 3>>& tris, int* i_hi, int* j_lo);
  bool side_refused(int a, int b);

  const std::vector<Vec3>& p_;
  const int n_;
  const std::function<bool(int, int, int)>& allowed_;
  const std::function<bool(int, int)>& side_ok_;
  const std::function<bool()>& give_up_;
  std::vector<double> W_;  // W_[at(i, j)]: lightest triangulation of the sub-polygon i..j
  std::vector<int> arg_;   // its apex m over side (i, j), -1: none
  std::vector<signed char> dead_;                               // side (i, j): 0 not asked, 1 passes, 2 refused
  int round_ = 0;                                               // rounds solved so far
  std::vector<int> marked_, changed_;  // at(i, j) -> last round it had a new refusal / a new value
  std::unordered_map<std::size_t, std::vector<int>> refused_;   // at(i, j) -> refused apexes m, sorted
  std::unordered_set<std::uint64_t> passed_;                    // triangles `allowed` accepted
  const bool lightest_first_;                                   // with side_ok: one eager pass
  bool gave_up_ = false;
  std::vector<std::pair<double, int>> order_;                   // a subproblem's candidates (w, m)
};

// Subproblem (i, j): the lightest triangle (i, m, j) over triangulated sides, smallest m on ties.
void LazyMinArea::solve(int i, int j) {
  if (lightest_first_) return solve_lightest_first(i, j);
  double best = kNone;
  int best_m = -1;
  if (dead_.empty() || dead_[at(i, j)] != 2) {
    const auto it = refused_.find(at(i, j));
    const int* skip = it == refused_.end() ? nullptr : it->second.data();
    const int* skip_end = skip ? skip + it->second.size() : nullptr;
    for (int m = i + 1; m < j; ++m) {
      if (skip != skip_end && *skip == m) {
        ++skip;
        continue;
      }
      const double sides = W_[at(i, m)] + W_[at(m, j)];
      if (!(sides < best)) continue;  // area >= 0: w = sides + area cannot be lighter
      const double w = sides + area(i, m, j);
      if (w < best) best = w, best_m = m;
    }
  }
  W_[at(i, j)] = best;
  arg_[at(i, j)] = best_m;
}

// With side_ok (restricted caps, whose queries are grid queries and refuse most candidates on a
// ring that runs along a wall): the candidates (w, m) over sides with a triangulation are taken
// lightest first (smallest m on ties) until `allowed` passes one; none is asked when side (i, j)
// is refused (then so would be every triangle on it). Lazy rounds cost more here (real CT
// surface, issue 26 session 19: 100-940 rounds per ring of 87-173 vertices, 2.6 s of CPU for its
// 16 restricted triangulations against 1.5 s lightest first). The lightest comes from a scan
// that skips the candidates whose sides alone weigh as much (as solve() does); only when it is
// refused are all candidates formed and taken from a min-heap (session 34: most subproblems
// stop at their lightest, and forming every candidate's area was most of the programme's time).
void LazyMinArea::solve_lightest_first(int i, int j) {
  double best = kNone;
  int best_m = -1;
  for (int m = i + 1; m < j; ++m) {
    const double sides = W_[at(i, m)] + W_[at(m, j)];
    if (!(sides < best)) continue;  // area >= 0: w = sides + area cannot be lighter
    const double w = sides + area(i, m, j);
    if (w < best) best = w, best_m = m;
  }
  if (best_m >= 0 && (side_refused(i, j) || !allowed_(i, best_m, j))) {
    const int refused = side_refused(i, j) ? -1 : best_m;
    best = kNone, best_m = -1;
    if (refused >= 0) lighter_than_refused(i, j, refused, &best, &best_m);
  }
  W_[at(i, j)] = best;
  arg_[at(i, j)] = best_m;
}

// The next candidates of subproblem (i, j) after its lightest, `refused`, was refused: every
// finite (w, m) but that one from a min-heap, lightest first, until `allowed` passes one.
void LazyMinArea::lighter_than_refused(int i, int j, int refused, double* best, int* best_m) {
  order_.clear();
  for (int m = i + 1; m < j; ++m) {
    const double w = W_[at(i, m)] + W_[at(m, j)] + area(i, m, j);
    if (w < kNone && m != refused) order_.push_back({w, m});
  }
  const auto later = std::greater<std::pair<double, int>>();
  std::make_heap(order_.begin(), order_.end(), later);
  for (auto end = order_.end(); end != order_.begin(); --end) {
    std::pop_heap(order_.begin(), end, later);
    const auto [w, m] = *(end - 1);
    if (allowed_(i, m, j)) {
      *best = w, *best_m = m;
      return;
    }
  }
}

// Solves again the subproblems (i, j) with i <= i_hi and j >= j_lo (those that contain a refusal),
// shortest first, but only those marked this round or whose chosen apex has a side whose value
// changed this round: refusals only accumulate, so values only grow, and a subproblem whose
// chosen triangle and sides kept their values keeps its value and its apex (every other
// candidate only grew). Round 0 solves everything.
void LazyMinArea::solve_around(int i_hi, int j_lo) {
  for (int len = 2; len < n_; ++len) {
    for (int i = std::max(0, j_lo - len); i <= i_hi && i + len < n_; ++i) {
      const int j = i + len, m = arg_[at(i, j)];
      const bool stale = round_ == 0 || marked_[at(i, j)] == round_ ||
                         (m >= 0 && (changed_[at(i, m)] == round_ || changed_[at(m, j)] == round_));
      if (!stale) continue;
      const double before = W_[at(i, j)];
      solve(i, j);
      if (!changed_.empty() && W_[at(i, j)] != before) changed_[at(i, j)] = round_;
    }
    if (lightest_first_ && give_up_ && give_up_()) {  // after each length
      gave_up_ = true;
      return;
    }
  }
}

std::vector<std::array<int, 3>> LazyMinArea::extract() const {
  std::vector<std::array<int, 3>> tris;
  std::vector<std::pair<int, int>> stack{{0, n_ - 1}};
  while (!stack.empty()) {
    auto [i, j] = stack.back();
    stack.pop_back();
    if (j - i < 2) continue;
    const int m = arg_[at(i, j)];
    if (m < 0) return {};  // every triangulation uses a refused triangle
    tris.push_back({i, m, j});
    stack.push_back({i, m});
    stack.push_back({m, j});
  }
  std::reverse(tris.begin(), tris.end());  // every triangle after the ones inside its sub-polygons
  return tris;
}

bool LazyMinArea::side_refused(int a, int b) {
  if (dead_.empty() || b - a == 1 || (a == 0 && b == n_ - 1)) return false;  // a ring edge
  signed char& s = dead_[at(a, b)];
  if (s == 0) s = side_ok_(a, b) ? 1 : 2;
  return s == 2;
}

// Asks about the solution's triangles; records the refused ones (and refused sides) and widens
// [0, i_hi] x [j_lo, n) to every subproblem that contains one. True when all passed.
bool LazyMinArea::refuse_failing(const std::vector<std::array<int, 3>>& tris, int* i_hi, int* j_lo) {
  bool all = true;
  auto mark = [&](int i, int j) {
    *i_hi = std::max(*i_hi, i), *j_lo = std::min(*j_lo, j), all = false;
    marked_[at(i, j)] = round_ + 1;
  };
  for (const auto& [i, m, j] : tris) {
    bool side_bad = false;
    for (const auto& [a, b] : {std::pair{i, m}, std::pair{m, j}, std::pair{i, j}})
      if (side_refused(a, b)) side_bad = true, mark(a, b);
    if (side_bad) continue;
    const std::uint64_t key = (std::uint64_t(i) * n_ + m) * n_ + j;
    if (passed_.count(key)) continue;
    if (!allowed_ || allowed_(i, m, j)) {
      passed_.insert(key);
      continue;
    }
    auto& r = refused_[at(i, j)];
    r.insert(std::lower_bound(r.begin(), r.end(), m), m);
    mark(i, j);
  }
  return all;
}

std::vector<std::array<int, 3>> LazyMinArea::run() {
  if (n_ < 3) return {};
  solve_around(n_ - 1, 0);
  if (gave_up_) return {};
  if (!allowed_ || lightest_first_) return extract();
  for (;;) {
    std::vector<std::array<int, 3>> tris = extract();
    if (tris.empty()) return {};
    int i_hi = -1, j_lo = n_;
    if (refuse_failing(tris, &i_hi, &j_lo)) return tris;
    if (give_up_ && give_up_()) return {};  // between rounds
    ++round_;
    solve_around(i_hi, j_lo);
  }
}

}  // namespace

std::vector<std::array<int, 3>> min_area_triangulation(const std::vector<Vec3>& ring,
                                                        const std::function<bool(int, int, int)>& allowed,
                                                        const std::function<bool()>& give_up,
                                                        const std::function<bool(int, int)>& side_ok) {
  return LazyMinArea(ring, allowed, side_ok, give_up).run();
}

std::vector<std::array<int, 3>> triangulate_ring(
    const Mesh& mesh, const std::vector<Mesh::VertexHandle>& ring,
    const std::function<bool(Mesh::VertexHandle, Mesh::VertexHandle)>& blocked, const FaceGrid* grid,
    const std::vector<std::array<int, 3>>& others, long long* budget, RingQueryCache* cache,
    const std::atomic<bool>* cancel) {
  const int n = static_cast<int>(ring.size());
  long long queries = 0;
  std::vector<Vec3> pts;
  for (auto v : ring) pts.push_back(mesh.point(v));
  auto diagonal_ok = [&](int a, int b) {
    if (std::abs(a - b) == 1 || std::abs(a - b) == n - 1) return true;  // a ring edge
    return !blocked(ring[a], ring[b]);
  };
  // A diagonal that pierces the surface fails every triangle on it (one segment query for all).
  std::function<bool(int, int)> side_ok;
  auto pierces = [&](int a, int b) {
    if (!cache) return grid->segment_hits(mesh, ring[a].idx(), ring[b].idx());
    const auto [it, added] = cache->sides_ok.try_emplace(static_cast<long long>(a) * n + b, false);
    if (added) it->second = !grid->segment_hits(mesh, ring[a].idx(), ring[b].idx());
    return !it->second;
  };
  if (grid) side_ok = [&](int a, int b) { return diagonal_ok(a, b) && !pierces(a, b); };
  auto allowed = [&](int i, int m, int j) {
    const Vec3 &a = pts[i], &b = pts[m], &c = pts[j];
    const double longest = std::max({(b - a).sqrnorm(), (c - b).sqrnorm(), (a - c).sqrnorm()});
    if (OpenMesh::cross(b - a, c - a).norm() < 1e-4 * longest) return false;
    if (!grid) return true;  // diagonals are checked on the result: cheaper than here
    ++queries;
    const long long key = (static_cast<long long>(i) * n + m) * n + j;
    if (cache && cache->hits.count(key)) return false;
    if (cache && others.empty() && cache->clean.count(key)) return true;
    const bool hit = grid->hits(mesh, {ring[i].idx(), ring[m].idx(), ring[j].idx()}, others);
    if (cache && !hit) cache->clean.insert(key);
    if (cache && hit && others.empty()) cache->hits.insert(key);
    return !hit;
  };
  auto give_up = [&] { return (budget && queries > *budget) || (cancel && *cancel); };
  const double cpu0 = grid && detail::denoise_debug() ? process_cpu_seconds() : 0.0;
  std::vector<std::array<int, 3>> t = min_area_triangulation(pts, allowed, give_up, side_ok);
  if (grid && detail::denoise_debug() && n >= 48 && !(cancel && *cancel))
    std::fprintf(stderr, "denoise debug: restricted triangulation of %d vertices: %lld grid queries, %s, CPU %.3f s\n",
                 n, queries,
                 t.empty() ? "none" : "found", process_cpu_seconds() - cpu0);
  if (budget) *budget -= queries;
  for (auto& tri : t) {
    for (int e = 0; e < 3; ++e)
      if (!diagonal_ok(tri[e], tri[(e + 1) % 3])) return {};
    for (int& i : tri) i = ring[i].idx();
  }
  return t;
}

void add_cap(Mesh& mesh, const std::vector<std::array<int, 3>>& tris, FaceGrid* grid, const char* what) {
  for (const auto& t : tris) {
    const auto f = mesh.add_face(Mesh::VertexHandle(t[0]), Mesh::VertexHandle(t[1]), Mesh::VertexHandle(t[2]));
    if (!f.is_valid()) throw Error(std::string(what) + ": could not add a cap triangle");
    if (grid) grid->insert(mesh, f);
  }
}

}  // namespace cf
