#include "colonflat/denoise/cap_triangulation.h"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>

#include "colonflat/core/error.h"
#include "denoise_debug.h"

namespace cf {

std::vector<std::array<int, 3>> min_area_triangulation(const std::vector<Vec3>& ring,
                                                        const std::function<bool(int, int, int)>& allowed,
                                                        const std::function<bool()>& give_up) {
  const int n = static_cast<int>(ring.size());
  std::vector<std::array<int, 3>> tris;
  if (n < 3) return tris;
  auto area = [&](int i, int m, int j) { return 0.5 * OpenMesh::cross(ring[m] - ring[i], ring[j] - ring[i]).norm(); };
  std::vector<double> W(static_cast<std::size_t>(n) * n, 0.0);
  std::vector<int> arg(static_cast<std::size_t>(n) * n, -1);
  constexpr double kNone = std::numeric_limits<double>::infinity();
  // Subproblem (i, j): the lightest triangle (i, m, j) over triangulated sides. With `allowed`
  // (a grid query per triangle), the candidates are tried lightest first until one passes: in
  // the order of m it ran for every m that improved on the lightest allowed one so far, which on
  // a twisted loop whose triangles mostly cross the surface is nearly every m.
  auto solve = [&](int i, int j, std::vector<std::pair<double, int>>& order) {
    double best = kNone;
    int best_m = -1;
    order.clear();
    for (int m = i + 1; m < j; ++m) {
      const double w = W[std::size_t(i) * n + m] + W[std::size_t(m) * n + j] + area(i, m, j);
      if (!(w < kNone)) continue;  // a side has no triangulation
      if (allowed) order.push_back({w, m});
      else if (w < best) best = w, best_m = m;
    }
    std::sort(order.begin(), order.end());
    for (const auto& [w, m] : order)
      if (allowed(i, m, j)) {
        best = w, best_m = m;
        break;
      }
    W[std::size_t(i) * n + j] = best;
    arg[std::size_t(i) * n + j] = best_m;
  };
  // One thread: splitting each length's subproblems over threads (one start and join per length,
  // n - 2 per triangulation) cost more wall time than it saved (issue 26, session 18: real CT
  // surface at 2 threads and load 4-6, surgery 11.7-17.0 s wall with the split, 6.1-6.3 s without,
  // 5.3-5.6 s at 1 thread; same output).
  std::vector<std::pair<double, int>> order;
  for (int len = 2; len < n; ++len) {
    for (int i = 0; i + len < n; ++i) solve(i, i + len, order);
    if (give_up && give_up()) return {};  // between lengths
  }
  std::vector<std::pair<int, int>> stack{{0, n - 1}};
  while (!stack.empty()) {
    auto [i, j] = stack.back();
    stack.pop_back();
    if (j - i < 2) continue;
    const int m = arg[std::size_t(i) * n + j];
    if (m < 0) return {};  // every triangulation uses a forbidden triangle
    tris.push_back({i, m, j});
    stack.push_back({i, m});
    stack.push_back({m, j});
  }
  std::reverse(tris.begin(), tris.end());  // every triangle after the ones inside its sub-polygons
  return tris;
}

std::vector<std::array<int, 3>> triangulate_ring(
    const Mesh& mesh, const std::vector<Mesh::VertexHandle>& ring,
    const std::function<bool(Mesh::VertexHandle, Mesh::VertexHandle)>& blocked, const FaceGrid* grid,
    const std::vector<std::array<int, 3>>& others, long long* budget) {
  const int n = static_cast<int>(ring.size());
  std::atomic<long long> queries{0};
  std::vector<Vec3> pts;
  for (auto v : ring) pts.push_back(mesh.point(v));
  auto diagonal_ok = [&](int a, int b) {
    if (std::abs(a - b) == 1 || std::abs(a - b) == n - 1) return true;  // a ring edge
    return !blocked(ring[a], ring[b]);
  };
  // Per diagonal: 0 not asked yet, 1 clear, 2 pierces the surface (then so does every triangle on
  // it: k^2 / 2 segment queries spare most of the k^3 / 6 triangle queries on rings whose
  // triangles mostly cross the surface). Threads may ask the same diagonal: same answer.
  std::vector<std::atomic<signed char>> chord(grid ? std::size_t(n) * n : 0);
  auto pierces = [&](int a, int b) {
    if (std::abs(a - b) == 1 || std::abs(a - b) == n - 1) return false;  // a ring edge
    auto& c = chord[std::size_t(a) * n + b];
    if (c.load(std::memory_order_relaxed) == 0)
      c.store(grid->segment_hits(mesh, ring[a].idx(), ring[b].idx()) ? 2 : 1, std::memory_order_relaxed);
    return c.load(std::memory_order_relaxed) == 2;
  };
  auto allowed = [&](int i, int m, int j) {
    const Vec3 &a = pts[i], &b = pts[m], &c = pts[j];
    const double longest = std::max({(b - a).sqrnorm(), (c - b).sqrnorm(), (a - c).sqrnorm()});
    if (OpenMesh::cross(b - a, c - a).norm() < 1e-4 * longest) return false;
    if (!grid) return true;  // diagonals are checked on the result: cheaper than here
    if (!diagonal_ok(i, m) || !diagonal_ok(m, j) || !diagonal_ok(i, j)) return false;
    if (pierces(i, m) || pierces(m, j) || pierces(i, j)) return false;
    ++queries;
    return !grid->hits(mesh, {ring[i].idx(), ring[m].idx(), ring[j].idx()}, others);
  };
  auto give_up = [&] { return budget && queries.load() > *budget; };
  std::vector<std::array<int, 3>> t = min_area_triangulation(pts, allowed, give_up);
  if (grid && detail::denoise_debug() && n >= 48)
    std::fprintf(stderr, "denoise debug: restricted triangulation of %d vertices: %lld grid queries, %s\n", n,
                 queries.load(), t.empty() ? "none" : "found");
  if (budget) *budget -= queries.load();
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
