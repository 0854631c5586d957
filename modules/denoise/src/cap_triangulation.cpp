#include "colonflat/denoise/cap_triangulation.h"

#include <algorithm>
#include <limits>

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

}  // namespace cf
