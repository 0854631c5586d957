// nonzero_box (voxel_box.h): per row its first and last set voxel, per thread a box, merged.
#include "colonflat/core/voxel_box.h"

#include <algorithm>
#include <mutex>

#include "colonflat/core/threads.h"

namespace cf {
namespace {
// The box of slices [k0, k1) (lo = n when none is set).
VoxelBox slices_box(const unsigned char* d, const std::array<std::size_t, 3>& n, std::size_t k0, std::size_t k1) {
  VoxelBox b;
  b.lo = n;
  for (std::size_t k = k0; k < k1; ++k)
    for (std::size_t j = 0; j < n[1]; ++j) {
      const unsigned char* r = d + (k * n[1] + j) * n[0];
      std::size_t first = n[0], last = 0, cnt = 0;
      for (std::size_t i = 0; i < n[0]; ++i)
        if (r[i]) {
          if (first == n[0]) first = i;
          last = i;
          ++cnt;
        }
      if (!cnt) continue;
      b.count += cnt;
      b.lo = {std::min(b.lo[0], first), std::min(b.lo[1], j), std::min(b.lo[2], k)};
      b.hi = {std::max(b.hi[0], last), std::max(b.hi[1], j), std::max(b.hi[2], k)};
    }
  return b;
}
}  // namespace

VoxelBox nonzero_box(const unsigned char* d, const std::array<std::size_t, 3>& n) {
  VoxelBox box;
  box.lo = n;
  std::mutex mu;
  parallel_for(n[2], [&](std::size_t k0, std::size_t k1) {
    const VoxelBox b = slices_box(d, n, k0, k1);
    if (!b.count) return;
    std::lock_guard<std::mutex> lock(mu);
    box.count += b.count;
    for (int a = 0; a < 3; ++a) box.lo[a] = std::min(box.lo[a], b.lo[a]), box.hi[a] = std::max(box.hi[a], b.hi[a]);
  });
  return box;
}

}  // namespace cf
