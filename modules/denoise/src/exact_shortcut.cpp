// "Shortcut first" (exact_shortcut.h): the coarse surface, the d test, and the exact method's hook
// (ExactGreedy::shortcut_first) that replaces a wide handle pick that is a bypassed girth by the
// loop across the fused contact that the shortest path between the colon's ends runs through.
#include "exact_shortcut.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <queue>

#include "colonflat/core/loops.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/core/union_find.h"
#include "denoise_debug.h"
#include "exact_greedy.h"

namespace cf::detail {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
// A colon end's cap: the nodes within kTipDepth mm below the farthest point cover about a
// hemisphere of that depth on a tube end, pi * 10^2 ~ 300 mm2 plus the haustra's folds; the band
// where two routes meet covers 2 * kTipDepth times the girth (>= 1 500 mm2 on a colon).
constexpr double kTipDepth = 10.0;
constexpr double kTipArea = 1000.0;

// Cell coordinates of a point, packed (21 bits each, offset so that negative cells fit).
std::uint64_t cell_key(const Vec3& p, double cell) {
  auto c = [cell](double x) { return std::uint64_t(std::int64_t(std::floor(x / cell)) + (1 << 20)) & 0x1FFFFF; };
  return c(p[0]) << 42 | c(p[1]) << 21 | c(p[2]);
}

}  // namespace

// Union of the vertices joined by an edge inside one cell; nodes numbered in vertex order (the
// same graph for any thread count and run).
CoarseSurface::CoarseSurface(const Mesh& mesh, double cell) {
  const std::size_t n = mesh.n_vertices();
  std::vector<std::uint64_t> key(n);
  for (std::size_t v = 0; v < n; ++v) key[v] = cell_key(mesh.point(Mesh::VertexHandle(int(v))), cell);
  UnionFind pieces(n);
  for (auto e : mesh.edges()) {
    const int a = mesh.from_vertex_handle(mesh.halfedge_handle(e, 0)).idx();
    const int b = mesh.to_vertex_handle(mesh.halfedge_handle(e, 0)).idx();
    if (key[a] == key[b]) pieces.unite(std::uint32_t(a), std::uint32_t(b));
  }
  node_of_.assign(n, -1);
  std::vector<int> count;
  for (std::size_t v = 0; v < n; ++v) {
    const std::uint32_t r = pieces.find(std::uint32_t(v));
    if (node_of_[r] < 0) {
      node_of_[r] = int(centre_.size());
      centre_.push_back(Vec3(0, 0, 0));
      first_vertex_.push_back(int(v));
      count.push_back(0);
    }
    const int id = node_of_[r];
    node_of_[v] = id;
    centre_[id] += mesh.point(Mesh::VertexHandle(int(v)));
    ++count[id];
  }
  for (std::size_t i = 0; i < centre_.size(); ++i) centre_[i] /= double(count[i]);
  blocked_.assign(centre_.size(), 0);
  make_arcs(mesh);
}

// Node pairs joined by a mesh edge, both ways, in compressed rows: the vertices taken node by
// node (a counting sort), each node's neighbours told apart with a stamp (no sort of the edges).
void CoarseSurface::make_arcs(const Mesh& mesh) {
  const std::size_t nodes = centre_.size();
  std::vector<int> first(nodes + 1, 0), order(node_of_.size());
  for (int n : node_of_) ++first[n + 1];
  for (std::size_t i = 1; i <= nodes; ++i) first[i] += first[i - 1];
  std::vector<int> fill(first.begin(), first.end() - 1);
  for (std::size_t v = 0; v < node_of_.size(); ++v) order[fill[node_of_[v]]++] = int(v);
  std::vector<int> seen(nodes, -1);
  start_.assign(1, 0);
  for (std::size_t n = 0; n < nodes; ++n) {
    for (int i = first[n]; i < first[n + 1]; ++i)
      for (auto w : mesh.vv_range(Mesh::VertexHandle(order[i]))) {
        const int m = node_of_[w.idx()];
        if (m == int(n) || seen[m] == int(n)) continue;
        seen[m] = int(n);
        arcs_.push_back(m);
        arc_length_.push_back((centre_[n] - centre_[m]).norm());
      }
    start_.push_back(int(arcs_.size()));
  }
}

std::vector<int> CoarseSurface::nodes_of(const std::vector<int>& vertices) const {
  std::vector<int> nodes;
  for (int v : vertices)
    if (node_of(v) >= 0) nodes.push_back(node_of(v));
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  return nodes;
}

void CoarseSurface::block(const std::vector<int>& nodes) {
  for (int n : nodes) blocked_[n] = 1;
}

std::vector<double> CoarseSurface::distances(int from, const std::vector<int>& also, std::vector<int>* parent) const {
  std::vector<double> dist(size(), kInfinity);
  if (parent) parent->assign(size(), -1);
  auto open = [&](int n) { return !blocked_[n] && !std::binary_search(also.begin(), also.end(), n); };
  if (!open(from)) return dist;
  using Entry = std::pair<double, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> heap;
  dist[from] = 0;
  heap.push({0.0, from});
  while (!heap.empty()) {
    const auto [d, n] = heap.top();
    heap.pop();
    if (d > dist[n]) continue;
    for (int a = start_[n]; a < start_[n + 1]; ++a) {
      const int m = arcs_[a];
      const double dm = d + arc_length_[a];
      if (dm >= dist[m] || !open(m)) continue;
      dist[m] = dm;
      if (parent) (*parent)[m] = n;
      heap.push({dm, m});
    }
  }
  return dist;
}

std::vector<int> CoarseSurface::path_to(int to, const std::vector<int>& parent) {
  std::vector<int> path;
  for (int n = to; n >= 0; n = parent[n]) path.push_back(n);
  std::reverse(path.begin(), path.end());
  return path;
}

// The farthest tip of a distance field: nodes are taken farthest first; the nodes within kTipDepth
// below a node, reached from it through such nodes, form a small cap at the end of a tube (a tip)
// but a wide band round the tube where two routes meet in the middle of a stretch that a fused
// contact bypasses (the band spans the whole girth: > kTipArea); a band's nodes are passed over.
// -1: none but the source.
static int farthest_tip(const CoarseSurface& g, const std::vector<double>& dist, double cell) {
  std::vector<int> order;
  for (std::size_t i = 0; i < dist.size(); ++i)
    if (std::isfinite(dist[i]) && dist[i] > 0) order.push_back(int(i));
  std::sort(order.begin(), order.end(), [&](int x, int y) { return dist[x] != dist[y] ? dist[x] > dist[y] : x < y; });
  std::vector<std::uint8_t> seen(dist.size(), 0);
  const double most = kTipArea / (cell * cell);  // nodes of a tip's cap at most
  for (int c : order) {
    if (seen[c]) continue;
    std::vector<int> cap{c};
    seen[c] = 1;
    for (std::size_t i = 0; i < cap.size(); ++i)
      for (int a = g.arc_start(cap[i]); a < g.arc_start(cap[i] + 1); ++a) {
        const int m = g.arc_node(a);
        if (!seen[m] && std::isfinite(dist[m]) && dist[m] >= dist[c] - kTipDepth) seen[m] = 1, cap.push_back(m);
      }
    if (double(cap.size()) <= most) return c;
  }
  return order.empty() ? -1 : order.front();
}

std::pair<int, int> ShortcutPaths::ends(int component, int start) {
  const auto it = ends_.find(component);
  if (it != ends_.end()) return it->second;
  const int a = farthest_tip(coarse_, coarse_.distances(coarse_.node_of(start)), cell_);
  const int b = a < 0 ? -1 : farthest_tip(coarse_, coarse_.distances(a), cell_);
  if (denoise_debug() && a >= 0 && b >= 0) {
    const Vec3 pa = centre_of(a), pb = centre_of(b);
    std::fprintf(stderr, "denoise debug: shortcut: ends of component %d: (%.1f %.1f %.1f) and (%.1f %.1f %.1f)\n", component,
                 pa[0], pa[1], pa[2], pb[0], pb[1], pb[2]);
  }
  return ends_[component] = {a, b};
}

ShortcutTest ShortcutPaths::test(const std::vector<int>& loop, int component, int start) {
  ShortcutTest t;
  const auto [a, b] = ends(component, start);
  if (a < 0 || b < 0 || a == b) return t;
  std::vector<int> parent;
  t.before = coarse_.distances(a, {}, &parent)[b];
  if (!std::isfinite(t.before)) return t;
  t.measured = true;
  t.path = CoarseSurface::path_to(b, parent);
  t.after = coarse_.distances(a, coarse_.nodes_of(loop))[b];
  return t;
}

std::vector<Mesh::VertexHandle> mesh_path_along(const Mesh& mesh, const CoarseSurface& coarse,
                                                const std::vector<int>& nodes, int from, int to) {
  std::vector<std::uint8_t> corridor(coarse.size(), 0);
  for (int n : nodes)
    for (int a = coarse.arc_start(n); a < coarse.arc_start(n + 1); ++a) corridor[coarse.arc_node(a)] = 1;
  for (int n : nodes) corridor[n] = 1;
  for (std::size_t n = 0; n < coarse.size(); ++n) corridor[n] &= coarse.blocked(int(n)) ? 0 : 1;
  std::vector<double> dist(mesh.n_vertices(), kInfinity);
  std::vector<int> parent(mesh.n_vertices(), -1);
  using Entry = std::pair<double, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> heap;
  dist[from] = 0;
  heap.push({0.0, from});
  while (!heap.empty() && heap.top().second != to) {
    const auto [d, v] = heap.top();
    heap.pop();
    if (d > dist[v]) continue;
    for (auto w : mesh.vv_range(Mesh::VertexHandle(v))) {
      const int node = coarse.node_of(w.idx());
      if (node < 0 || !corridor[node] || mesh.is_boundary(w)) continue;
      const double dw = d + (mesh.point(w) - mesh.point(Mesh::VertexHandle(v))).norm();
      if (dw >= dist[w.idx()]) continue;
      dist[w.idx()] = dw;
      parent[w.idx()] = v;
      heap.push({dw, w.idx()});
    }
  }
  std::vector<Mesh::VertexHandle> path;
  if (!std::isfinite(dist[to])) return path;
  for (int v = to; v >= 0; v = parent[v]) path.push_back(Mesh::VertexHandle(v));
  std::reverse(path.begin(), path.end());
  return path;
}

double loop_diameter(const Mesh& mesh, const std::vector<Mesh::VertexHandle>& loop) {
  std::vector<Vec3> points;
  points.reserve(loop.size());
  for (auto v : loop) points.push_back(mesh.point(v));
  return points_diameter(points);
}

// ---- the exact method's hook ----

// Vertex ids of the coarse graph for a loop of the current mesh: a vertex created after the graph
// was built stands for the input vertex it copies (cap vertices for none).
std::vector<int> ExactGreedy::shortcut_ids(const std::vector<Mesh::VertexHandle>& loop) const {
  std::vector<int> ids;
  for (auto v : loop) ids.push_back(shortcut_->coarse().node_of(v.idx()) >= 0 ? v.idx() : st_.origin[v.idx()]);
  return ids;
}

bool ExactGreedy::lengthens(const ShortcutTest& t) const {
  return t.measured && t.after > t.before + opts_.shortcut_gain;
}

bool ExactGreedy::keeps_shortcut(const std::vector<Mesh::VertexHandle>& loop) {
  const std::vector<int> ids = shortcut_ids(loop);
  return lengthens(shortcut_->test(ids, st_.component[loop.front().idx()], ids.front()));
}

// Whether the greedy's pick is a handle loop at least shortcut_diameter wide (policy shortest);
// then the coarse graph is built if it was not (before the cut, which the test needs).
bool ExactGreedy::shortcut_gate(const std::vector<Mesh::VertexHandle>& pick) {
  if (want_type_ || opts_.shortcut_diameter <= 0) return false;
  if (loop_diameter(st_.mesh, pick) < opts_.shortcut_diameter) return false;
  if (classify_loop(st_.mesh, pick) != LoopType::kHandle) return false;
  Stopwatch sw;
  if (!shortcut_) shortcut_ = std::make_unique<ShortcutPaths>(st_.mesh, opts_.shortcut_cell);
  shortcut_s_ += sw.seconds();
  return true;
}

// After a wide pick was cut (`done`; *loop: the loop cut, `pick` or cut_cleanly()'s replacement):
// kept when the cut lengthens d (exact_shortcut.h); otherwise undone, and the shortest
// non-separating loop across d's current path (within shortcut_reach times the cut's length) whose
// cut lengthens d is cut instead (its caps' alternatives must lengthen d too); without one `pick`
// is cut again as before. *loop and *cut_class receive the loop cut and its class.
SurgeryResult ExactGreedy::shortcut_first(const SurgeryResult& done, int iteration, const std::vector<Mesh::VertexHandle>& pick,
                                          std::vector<Mesh::VertexHandle>* loop, std::vector<std::uint64_t>* cut_class) {
  Stopwatch sw;
  ++shortcut_tests_;
  const std::vector<int> ids = shortcut_ids(*loop);
  int start = -1;
  for (int id : ids) start = start < 0 && shortcut_->coarse().node_of(id) >= 0 ? id : start;
  const ShortcutTest t = start < 0 ? ShortcutTest{} : shortcut_->test(ids, st_.component[loop->front().idx()], start);
  const double length = st_.loops.back().length;
  if (denoise_debug())
    std::fprintf(stderr, "denoise debug: shortcut test at cut %d: %.1f mm (diameter %.1f mm): d %.1f -> %.1f mm\n",
                 iteration, length, st_.loops.back().diameter_mm, t.before, t.after);
  if (!t.measured || lengthens(t)) return shortcut_s_ += sw.seconds(), done;
  revert_cut(done);
  const std::vector<Mesh::VertexHandle> other = across_path(t, length);
  if (other.empty()) {  // cut as before (the same surgery: the same mesh and loop)
    shortcut_s_ += sw.seconds();
    *cut_class = search_->cycle_class(pick);
    std::vector<std::uint64_t> reduced = *cut_class;
    span_.reduce(reduced.data());
    return cut_cleanly(pick, reduced, iteration, cut_class, loop);
  }
  ++shortcut_replaced_;
  *cut_class = search_->cycle_class(other);
  std::vector<std::uint64_t> reduced = *cut_class;
  span_.reduce(reduced.data());
  shortcut_s_ += sw.seconds();
  shortcut_guard_ = true;
  SurgeryResult sr = cut_cleanly(other, reduced, iteration, cut_class, loop);
  shortcut_guard_ = false;
  return sr;
}

// The loop across the path of `t` that lengthens d (searched to shortcut_reach times `length`),
// or none.
std::vector<Mesh::VertexHandle> ExactGreedy::across_path(const ShortcutTest& t, double length) {
  const CoarseSurface& coarse = shortcut_->coarse();
  const std::vector<Mesh::VertexHandle> path =
      mesh_path_along(st_.mesh, coarse, t.path, coarse.vertex_of(t.path.front()), coarse.vertex_of(t.path.back()));
  if (path.size() < 3) return {};
  const std::vector<Mesh::VertexHandle> other = loop_across(path, opts_.shortcut_reach * length, kShortcutSpacing * length);
  if (other.empty()) return {};
  const std::vector<int> ids = shortcut_ids(other);
  const ShortcutTest u = shortcut_->test(ids, st_.component[other.front().idx()], ids.front());
  if (denoise_debug())
    std::fprintf(stderr, "denoise debug: shortcut: candidate %.1f mm: d %.1f -> %.1f mm\n", loop_length(st_.mesh, other),
                 u.before, u.after);
  return lengthens(u) ? other : std::vector<Mesh::VertexHandle>{};
}

// The shortest non-separating loop crossing `path` an odd number of times (so it crosses it),
// shorter than `limit`: searched from the path's vertices every `spacing` mm (the loop found
// through a source within spacing / 2 of the crossing is at most `spacing` longer), then again
// from the found loop's vertices, which finds the loop round the opening without the detour.
std::vector<Mesh::VertexHandle> ExactGreedy::loop_across(const std::vector<Mesh::VertexHandle>& path, double limit,
                                                         double spacing) {
  const std::vector<std::uint8_t> cochain = crossing_cochain(st_.mesh, path, false);
  FundamentalCycleSearch::Accept non_separating = [this](const std::vector<Mesh::VertexHandle>& cycle) {
    std::vector<std::uint64_t> cls = search_->cycle_class(cycle);
    return !span_.reduce(cls.data());
  };
  std::vector<Mesh::VertexHandle> sources;
  double since = spacing;
  for (std::size_t i = 1; i + 1 < path.size(); ++i) {
    since += (st_.mesh.point(path[i]) - st_.mesh.point(path[i - 1])).norm();
    if (since >= spacing) sources.push_back(path[i]), since = 0;
  }
  Stopwatch sw;
  const long long settled0 = settled_;
  std::vector<Mesh::VertexHandle> found =
      shortest_from_spread(sources, limit, &non_separating, &cochain, nullptr, sources.size());
  if (denoise_debug())
    std::fprintf(stderr, "denoise debug: shortcut: path %zu vertices, %zu sources, limit %.1f mm: %s %.1f mm, %.3f s, %lld settled\n",
                 path.size(), sources.size(), limit, found.empty() ? "none" : "found", found.empty() ? 0.0 : loop_length(st_.mesh, found),
                 sw.seconds(), settled_ - settled0);
  if (found.empty()) return found;
  const double value = loop_length(st_.mesh, found);
  std::vector<Mesh::VertexHandle> tighter =
      shortest_from_spread(found, value * (1 + 1e-9), &non_separating, &cochain, nullptr, kFallbackSources);
  if (denoise_debug())
    std::fprintf(stderr, "denoise debug: shortcut: tighter %.1f mm, %.3f s\n", tighter.empty() ? 0.0 : loop_length(st_.mesh, tighter), sw.seconds());
  return tighter.empty() ? found : tighter;
}

}  // namespace cf::detail
