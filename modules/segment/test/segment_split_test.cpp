// The fluid pieces' growth split over the workers (segment_split.cpp): the bright components' owners
// (largest first to the least-loaded worker) and the growth per worker against one serial growth, on
// small random volumes with analytic component sizes.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "../src/segment_internal.h"
#include "segment_dims.h"
#include "colonflat/core/threads.h"

namespace cf::segment_detail {
namespace {

// Bright boxes along x separated by empty planes: [x0, x1) x all y x all z for each (x0, x1).
Bytes slabs(const Dims& d, const std::vector<std::pair<std::size_t, std::size_t>>& xs) {
  Bytes m(d.total, 0);
  for (std::size_t q = 0; q < d.total; ++q)
    for (const auto& [x0, x1] : xs) m[q] |= q % d.n[0] >= x0 && q % d.n[0] < x1;
  return m;
}

// Four slabs of 4, 3, 2 and 1 columns (voxels 4u, 3u, 2u, 1u with u = ny * nz), cells of one voxel:
// with 2 workers the largest goes to worker 0, the next to 1, the third to 1 (load 3 < 4) and the
// last to 0 (load 4 < 5); with 1 worker every voxel has owner 0.
TEST(SegmentSplit, ComponentOwnersLargestFirstToLeastLoadedWorker) {
  const Dims d = unit_dims(14, 5, 4);
  const Bytes m = slabs(d, {{0, 1}, {2, 4}, {5, 8}, {9, 13}});  // sizes 1, 2, 3, 4 columns
  const ComponentOwners owners(m, d, 2, 1);
  const unsigned char expect_at_x[14] = {0, 9, 1, 1, 9, 1, 1, 1, 9, 0, 0, 0, 0, 9};  // 9: not in the mask
  const ComponentOwners one(m, d, 1, 1);
  for (std::size_t q = 0; q < d.total; ++q)
    if (m[q]) {
      ASSERT_EQ(owners.at(q), expect_at_x[q % d.n[0]]) << "voxel " << q;
      ASSERT_EQ(one.at(q), 0) << "voxel " << q;
    }
}

// Cells of 4 voxels join components in set face-neighbouring cells: slabs x in [0, 4), [8, 11) and
// [12, 14) (4, 3 and 2 columns) are three components, but the last two share cells 2 and 3 (x 8-11,
// 12-15), so they are one owner's (5 columns, worker 0) and the first is worker 1's.
TEST(SegmentSplit, ComponentOwnersOnCellsJoinComponentsInNeighbouringCells) {
  const Dims d = unit_dims(14, 6, 5);
  const Bytes m = slabs(d, {{0, 4}, {8, 11}, {12, 14}});
  const ComponentOwners owners(m, d, 2, 4);
  for (std::size_t q = 0; q < d.total; ++q)
    if (m[q]) ASSERT_EQ(owners.at(q), q % d.n[0] < 4 ? 1 : 0) << "voxel " << q;
}

// The growth split by component over 2 and 3 workers (owners on the stage's 4-voxel cells) labels
// every voxel as one serial growth of the whole queue does (same nearest seed, same tie-breaking by
// queue order, walls entered only in the second pass), and grows one queue per worker: 3 slabs of
// random bright voxels (70 % fluid, 30 % wall) two empty cells apart, seeds in every slab in random order.
TEST(SegmentSplit, GrowthPerWorkerEqualsOneSerialGrowth) {
  const Dims d = unit_dims(32, 12, 10);
  Bytes bright = slabs(d, {{0, 8}, {12, 20}, {24, 32}});
  std::mt19937 rng(5);
  std::vector<float> hu(d.total);
  for (std::size_t q = 0; q < d.total; ++q) {
    bright[q] = bright[q] && rng() % 10 < 8;
    hu[q] = rng() % 10 < 7 ? 400.0f : 50.0f;
  }
  std::vector<std::size_t> seeds;
  for (std::size_t q = 0; q < d.total; ++q)
    if (bright[q] && hu[q] >= 200 && rng() % 40 == 0) seeds.push_back(q);
  std::shuffle(seeds.begin(), seeds.end(), rng);
  HuCrop crop;
  crop.copy(hu.data(), 1, d.total, [](std::size_t) { return std::size_t(0); });
  auto grow = [&](const ComponentOwners& owners, std::size_t* used) {
    std::vector<std::uint32_t> label(d.total, 0);
    std::vector<std::size_t> queue = seeds;
    for (std::size_t t = 0; t < seeds.size(); ++t) label[seeds[t]] = std::uint32_t(t % 7 + 1);
    *used = grow_labels({&d, bright.data(), &crop, 200.0, label.data()}, owners, queue);
    EXPECT_TRUE(queue.empty());
    return label;
  };
  std::size_t used = 0;
  const std::vector<std::uint32_t> ref = grow(ComponentOwners(bright, d, 1, 4), &used);
  ASSERT_EQ(used, 1u);
  std::size_t reached = 0, walls = 0;
  for (std::size_t q = 0; q < d.total; ++q) reached += ref[q] != 0, walls += ref[q] && hu[q] < 200;
  EXPECT_GT(reached, d.total / 3);  // the growth got somewhere, through walls too
  EXPECT_GT(walls, 50u);
  for (std::size_t w : {2, 3}) {
    set_thread_count(int(w));
    EXPECT_TRUE(grow(ComponentOwners(bright, d, w, 4), &used) == ref) << w << " workers";
    EXPECT_EQ(used, w) << w << " workers";  // 3 slabs over w workers
  }
  set_thread_count(0);
}

}  // namespace
}  // namespace cf::segment_detail
