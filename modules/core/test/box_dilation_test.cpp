// dilate_box (box_dilation.cpp): binary box dilation of random volumes checked voxel by voxel
// against the brute-force OR over the box clipped at the volume's faces, with 1 and 3 threads
// (the parallel split of rows, slices and lines taken).
#include <gtest/gtest.h>

#include <array>
#include <cstddef>
#include <vector>

#include "colonflat/core/box_dilation.h"
#include "colonflat/core/threads.h"

namespace cf {
namespace {

using Volume = std::vector<unsigned char>;

// A volume of size n with about one voxel in `one_in` set (an LCG, so the test is reproducible);
// set voxels hold values other than 1 too (any non-zero byte is set).
Volume random_volume(const std::array<std::size_t, 3>& n, unsigned one_in) {
  Volume v(n[0] * n[1] * n[2], 0);
  unsigned state = 2463534242u;
  for (auto& b : v) {
    state = state * 1664525u + 1013904223u;
    b = (state >> 8) % one_in == 0 ? static_cast<unsigned char>(1 + (state >> 20) % 200) : 0;
  }
  return v;
}

// The OR of `v` over the box of half-widths r around each voxel, clipped at the faces.
Volume brute_force(const Volume& v, const std::array<std::size_t, 3>& n, const int r[3]) {
  Volume out(v.size(), 0);
  const long nx = long(n[0]), ny = long(n[1]), nz = long(n[2]);
  for (long k = 0; k < nz; ++k)
    for (long j = 0; j < ny; ++j)
      for (long i = 0; i < nx; ++i) {
        bool any = false;
        for (long c = std::max(0L, k - r[2]); c <= std::min(nz - 1, k + std::max(0, r[2])); ++c)
          for (long b = std::max(0L, j - r[1]); b <= std::min(ny - 1, j + std::max(0, r[1])); ++b)
            for (long a = std::max(0L, i - r[0]); a <= std::min(nx - 1, i + std::max(0, r[0])); ++a)
              any = any || v[std::size_t((c * ny + b) * nx + a)];
        out[std::size_t((k * ny + j) * nx + i)] = any;
      }
  return out;
}

// dilate_box of v (in place) with `threads` threads.
Volume dilated(Volume v, const std::array<std::size_t, 3>& n, const int r[3], int threads) {
  set_thread_count(threads);
  dilate_box(v.data(), n, r);
  set_thread_count(0);
  return v;
}

// Every voxel equals the brute-force box OR, for cubic and anisotropic boxes (one axis skipped),
// whatever the thread count; a sparse volume so that the result is neither empty nor full.
TEST(CoreBoxDilation, EqualsBruteForceForAnyThreadCount) {
  const std::array<std::size_t, 3> n{23, 17, 13};
  const Volume v = random_volume(n, 60);
  const int boxes[3][3] = {{2, 2, 2}, {1, 0, 3}, {0, 2, 1}};
  for (const auto& r : boxes) {
    const Volume expected = brute_force(v, n, r);
    std::size_t set = 0;
    for (auto b : expected) set += b;
    ASSERT_GT(set, expected.size() / 10);
    ASSERT_LT(set, expected.size());
    for (int threads : {1, 3}) EXPECT_EQ(dilated(v, n, r, threads), expected) << "threads " << threads;
  }
}

// No axis to dilate along: the volume is left as it is (not binarised).
TEST(CoreBoxDilation, ZeroRadiusLeavesTheInput) {
  const std::array<std::size_t, 3> n{5, 4, 3};
  const Volume v = random_volume(n, 3);
  const int r[3] = {0, 0, 0};
  EXPECT_EQ(dilated(v, n, r, 2), v);
}

// Half-widths of 255 voxels and more (the nearest-set-row sweeps in 32-bit positions) along y and
// along z equal the brute-force OR too, on lines long enough for the window to be cut on one side.
TEST(CoreBoxDilation, LongRadiiEqualBruteForce) {
  for (const auto& [n, r] : {std::pair<std::array<std::size_t, 3>, std::array<int, 3>>{{3, 700, 2}, {0, 300, 0}},
                             {{2, 3, 900}, {1, 0, 256}}}) {
    const Volume v = random_volume(n, 400);
    const Volume expected = brute_force(v, n, r.data());
    std::size_t set = 0;
    for (auto b : expected) set += b;
    ASSERT_GT(set, 0u);
    ASSERT_LT(set, expected.size());
    EXPECT_EQ(dilated(v, n, r.data(), 2), expected);
  }
}

}  // namespace
}  // namespace cf
