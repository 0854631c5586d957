// A disk-shaped patch opened along its ridge into an annulus (see patch_slit.h).
#include "patch_slit.h"

#include <algorithm>
#include <limits>

#include "colonflat/core/error.h"

namespace cf::flat_detail {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The shortest path in g from `to` back to the source of `d` (d: dijkstra from that one source),
// each step to the neighbour u with the least d[u] + edge length among those with d[u] < d[v]
// (the first in g's order on a tie): to, ..., source.
std::vector<int> path_back(const Csr& g, const std::vector<double>& d, int to) {
  std::vector<int> path{to};
  for (int v = to; d[std::size_t(v)] > 0;) {
    int best = -1;
    double best_d = kInf;
    for (int k = g.start[std::size_t(v)]; k < g.start[std::size_t(v) + 1]; ++k) {
      const int u = g.nbr[std::size_t(k)];
      const double via = d[std::size_t(u)] + g.len[std::size_t(k)];
      if (d[std::size_t(u)] < d[std::size_t(v)] && via < best_d) best_d = via, best = u;
    }
    if (best < 0) return {};
    path.push_back(v = best);
  }
  return path;
}

// The slit: the shortest path through the ridge (vertices at least kSlitRidge of the largest
// distance from the rim) between its two vertices farthest apart along it (from the farthest from
// the rim, the ridge vertex farthest from it, then the one farthest from that). Empty: no ridge.
std::vector<int> ridge_path(const Surface& s, const Edges& E) {
  Csr g = build_csr(s, E);
  std::vector<int> rim;  // the disk's rim: its boundary loops' vertices
  for (const std::vector<int>& loop : boundary_loops(s, E)) rim.insert(rim.end(), loop.begin(), loop.end());
  if (rim.empty()) return {};
  const std::vector<double> d = dijkstra(g, rim);
  const int top = argmax_finite(d);
  if (!(d[std::size_t(top)] > 0)) return {};
  const double ridge = kSlitRidge * d[std::size_t(top)];
  for (std::size_t v = 0; v + 1 < g.start.size(); ++v)
    for (int k = g.start[v]; k < g.start[v + 1]; ++k)
      if (!(d[v] >= ridge) || !(d[std::size_t(g.nbr[std::size_t(k)])] >= ridge)) g.len[std::size_t(k)] = kInf;
  const int a = argmax_finite(dijkstra(g, {top}));
  const std::vector<double> da = dijkstra(g, {a});
  return path_back(g, da, argmax_finite(da));
}

// The faces around path vertex v on the left of the path (those holding the directed edge
// v -> next, and the faces reached from it around v without crossing the edges to prev or next).
std::vector<int> left_fan(const Surface& s, const std::vector<std::vector<int>>& vf, int prev, int v, int next) {
  auto holds = [&](int f, int x) {
    const Tri& t = s.t[std::size_t(f)];
    return t[0] == x || t[1] == x || t[2] == x;
  };
  std::vector<int> fan, stack;
  for (int f : vf[std::size_t(v)]) {
    const Tri& t = s.t[std::size_t(f)];
    for (int j = 0; j < 3; ++j)
      if (t[std::size_t(j)] == v && t[std::size_t((j + 1) % 3)] == next) stack.push_back(f);
  }
  while (!stack.empty()) {
    const int f = stack.back();
    stack.pop_back();
    if (std::find(fan.begin(), fan.end(), f) != fan.end()) continue;
    fan.push_back(f);
    for (int x : s.t[std::size_t(f)]) {
      if (x == v || x == prev || x == next) continue;
      for (int g : vf[std::size_t(v)])  // the face across the edge v-x
        if (g != f && holds(g, x)) stack.push_back(g);
    }
  }
  return fan;
}

// Two boundary loops and Euler characteristic 0 (false also when an edge is not manifold).
bool two_loops(const Surface& s) {
  try {
    const Edges E = build_edges(s.t);
    const long long chi = (long long)s.p.size() - (long long)E.ev.size() + (long long)s.t.size();
    return boundary_loops(s, E).size() == 2 && chi == 0;
  } catch (const PreconditionError&) {
    return false;  // not a manifold after the cut
  }
}

// An annulus that stays one after the band's boundary clean-up (clean_face_set: faces with three
// corners on the boundary and pinches dropped, again and again): a slit that runs one face from the
// rim is unzipped into it there, and the band would be no tube.
bool is_annulus(const Surface& s) {
  if (!two_loops(s)) return false;
  std::vector<int> all(s.t.size());
  for (std::size_t f = 0; f < all.size(); ++f) all[f] = int(f);
  const std::vector<int> kept = clean_face_set(s, build_edges(s.t), std::move(all));
  if (kept.size() == s.t.size()) return true;
  std::vector<char> keep(s.t.size(), 0);
  for (int f : kept) keep[std::size_t(f)] = 1;
  return two_loops(sub_surface(s, keep));
}

}  // namespace

Surface slit_disk(const Surface& disk) {
  const Edges E = build_edges(disk.t);
  const std::vector<int> path = ridge_path(disk, E);
  if (path.size() < 3) return {};
  const std::vector<std::vector<int>> vf = vertex_faces(disk);
  std::vector<std::vector<int>> fans;  // per inner path vertex, from the uncut surface
  for (std::size_t i = 1; i + 1 < path.size(); ++i) fans.push_back(left_fan(disk, vf, path[i - 1], path[i], path[i + 1]));
  Surface out = disk;
  for (std::size_t i = 1; i + 1 < path.size(); ++i) {
    const int v = path[i], copy = int(out.p.size());
    out.p.push_back(disk.p[std::size_t(v)]);
    if (!disk.src.empty()) out.src.push_back(disk.src[std::size_t(v)]);
    for (int f : fans[i - 1])
      for (int& c : out.t[std::size_t(f)])
        if (c == v) c = copy;
  }
  std::vector<char> keep(out.t.size(), 1);  // the slit's two ends rounded: the faces around each end vertex dropped
  for (int end : {path.front(), path.back()})
    for (int f : vf[std::size_t(end)]) keep[std::size_t(f)] = 0;
  Surface rounded = sub_surface(out, keep);
  if (is_annulus(rounded)) return rounded;
  return is_annulus(out) ? out : Surface{};  // the ends as they are, where rounding them reaches the rim
}

}  // namespace cf::flat_detail
