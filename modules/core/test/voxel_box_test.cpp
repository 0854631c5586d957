// nonzero_box (voxel_box.cpp): the box and count of the set voxels against a voxel-by-voxel scan.
#include <gtest/gtest.h>

#include <vector>

#include "colonflat/core/threads.h"
#include "colonflat/core/voxel_box.h"

namespace cf {
namespace {

// A sparse volume with set bytes of several values, and a single voxel: the box and count equal
// those of a plain scan for 1 and 3 threads; an empty volume has count 0.
TEST(CoreVoxelBox, EqualsAPlainScanForAnyThreadCount) {
  const std::array<std::size_t, 3> n{19, 11, 13};
  std::vector<unsigned char> v(n[0] * n[1] * n[2], 0);
  unsigned state = 12345u;
  for (std::size_t q = 0; q < v.size(); ++q) {
    state = state * 1664525u + 1013904223u;
    const std::size_t i = q % n[0], j = (q / n[0]) % n[1], k = q / (n[0] * n[1]);
    if (i >= 3 && i <= 15 && j >= 2 && j <= 8 && k >= 4 && k <= 10 && (state >> 8) % 9 == 0) v[q] = 1 + (state >> 20) % 200;
  }
  VoxelBox want;
  want.lo = n;
  for (std::size_t q = 0; q < v.size(); ++q)
    if (v[q]) {
      const std::size_t c[3] = {q % n[0], (q / n[0]) % n[1], q / (n[0] * n[1])};
      ++want.count;
      for (int a = 0; a < 3; ++a) want.lo[a] = std::min(want.lo[a], c[a]), want.hi[a] = std::max(want.hi[a], c[a]);
    }
  ASSERT_GT(want.count, 10u);
  for (int threads : {1, 3}) {
    set_thread_count(threads);
    const VoxelBox got = nonzero_box(v.data(), n);
    set_thread_count(0);
    EXPECT_EQ(got.count, want.count) << threads;
    EXPECT_EQ(got.lo, want.lo) << threads;
    EXPECT_EQ(got.hi, want.hi) << threads;
  }
  std::vector<unsigned char> one(v.size(), 0);
  one[(7 * n[1] + 5) * n[0] + 2] = 1;
  const VoxelBox b = nonzero_box(one.data(), n);
  EXPECT_EQ(b.count, 1u);
  EXPECT_EQ(b.lo, (std::array<std::size_t, 3>{2, 5, 7}));
  EXPECT_EQ(b.hi, b.lo);
  EXPECT_EQ(nonzero_box(std::vector<unsigned char>(v.size(), 0).data(), n).count, 0u);
}

}  // namespace
}  // namespace cf
