#include "colonflat/denoise/cap_triangulation.h"

#include <algorithm>
#include <cstdlib>
#include <limits>
#include <string>

#include "colonflat/core/error.h"

namespace cf {

std::vector<std::array<int, 3>> min_area_triangulation(const std::vector<Vec3>& ring,
                                                        const std::function<bool(int, int, int)>& allowed) {
  const int n = static_cast<int>(ring.size());
  std::vector<std::array<int, 3>> tris;
  if (n < 3) return tris;
  auto area = [&](int i, int m, int j) { return 0.5 * OpenMesh::cross(ring[m] - ring[i], ring[j] - ring[i]).norm(); };
  std::vector<double> W(static_cast<std::size_t>(n) * n, 0.0);
  std::vector<int> arg(static_cast<std::size_t>(n) * n, -1);
  for (int len = 2; len < n; ++len)
    for (int i = 0; i + len < n; ++i) {
      const int j = i + len;
      double best = std::numeric_limits<double>::infinity();
      for (int m = i + 1; m < j; ++m) {
        const double w = W[std::size_t(i) * n + m] + W[std::size_t(m) * n + j] + area(i, m, j);
        if (w < best && (!allowed || allowed(i, m, j))) {
          best = w;
          arg[std::size_t(i) * n + j] = m;
        }
      }
      W[std::size_t(i) * n + j] = best;
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
    const std::vector<std::array<int, 3>>& others) {
  const int n = static_cast<int>(ring.size());
  std::vector<Vec3> pts;
  for (auto v : ring) pts.push_back(mesh.point(v));
  auto diagonal_ok = [&](int a, int b) {
    if (std::abs(a - b) == 1 || std::abs(a - b) == n - 1) return true;  // a ring edge
    return !blocked(ring[a], ring[b]);
  };
  auto allowed = [&](int i, int m, int j) {
    const Vec3 &a = pts[i], &b = pts[m], &c = pts[j];
    const double longest = std::max({(b - a).sqrnorm(), (c - b).sqrnorm(), (a - c).sqrnorm()});
    if (OpenMesh::cross(b - a, c - a).norm() < 1e-4 * longest) return false;
    if (!grid) return true;  // diagonals are checked on the result: cheaper than here
    if (!diagonal_ok(i, m) || !diagonal_ok(m, j) || !diagonal_ok(i, j)) return false;
    return !grid->hits(mesh, {ring[i].idx(), ring[m].idx(), ring[j].idx()}, others);
  };
  std::vector<std::array<int, 3>> t = min_area_triangulation(pts, allowed);
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
