#pragma once
// Test helper, independent of the library: voxel counts of the 6-connected components of a mask's
// non-zero voxels (breadth-first flood fill), in scan order of their first voxel.
#include <cstddef>
#include <queue>
#include <vector>

#include "colonflat/volume/volume_io.h"

namespace cf::testing {

inline std::vector<std::size_t> component_sizes_6(const MaskImage* m) {
  const auto sz = m->GetBufferedRegion().GetSize();
  const long nx = long(sz[0]), ny = long(sz[1]), nz = long(sz[2]);
  const unsigned char* d = m->GetBufferPointer();
  std::vector<char> seen(std::size_t(nx * ny * nz), 0);
  std::vector<std::size_t> sizes;
  for (long s = 0; s < nx * ny * nz; ++s) {
    if (!d[s] || seen[s]) continue;
    std::size_t count = 0;
    std::queue<long> q;
    q.push(s);
    seen[s] = 1;
    while (!q.empty()) {
      const long c = q.front();
      q.pop();
      ++count;
      const long i = c % nx, j = (c / nx) % ny, k = c / (nx * ny);
      const long nb[6][3] = {{i - 1, j, k}, {i + 1, j, k}, {i, j - 1, k}, {i, j + 1, k}, {i, j, k - 1}, {i, j, k + 1}};
      for (const auto& p : nb) {
        if (p[0] < 0 || p[1] < 0 || p[2] < 0 || p[0] >= nx || p[1] >= ny || p[2] >= nz) continue;
        const long id = (p[2] * ny + p[1]) * nx + p[0];
        if (d[id] && !seen[id]) {
          seen[id] = 1;
          q.push(id);
        }
      }
    }
    sizes.push_back(count);
  }
  return sizes;
}

}  // namespace cf::testing
