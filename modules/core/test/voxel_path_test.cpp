#include "colonflat/core/voxel_path.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace cf {
namespace {

// A volume of dims with every voxel inside.
struct Volume {
  std::array<int, 3> dims;
  std::vector<unsigned char> bytes;
  explicit Volume(std::array<int, 3> d, unsigned char fill = 1) : dims(d), bytes(std::size_t(d[0]) * d[1] * d[2], fill) {}
  unsigned char& at(int i, int j, int k) { return bytes[(std::size_t(k) * dims[1] + j) * dims[0] + i]; }
  VoxelBox box(std::array<double, 3> sp) const { return {bytes.data(), dims, sp, {0, 0, 0}, dims}; }
};

// Along a straight row of anisotropic voxels the path distance is the index difference times that axis' spacing.
TEST(VoxelPath, StraightRowGivesSpacingTimesSteps) {
  Volume v({10, 1, 1});
  const VoxelBox box = v.box({0.7, 1.0, 2.5});
  const std::vector<float> d = voxel_path_distance(box, {0, 0, 0});
  for (int i = 0; i < 10; ++i) EXPECT_NEAR(d[box.box_index(i, 0, 0)], 0.7 * i, 1e-5);
}

// In a full block the path to a voxel is the 26-neighbour (diagonal-first) length: max steps diagonal, rest straight.
TEST(VoxelPath, FullBlockGivesChamferDistance) {
  Volume v({6, 6, 6});
  const VoxelBox box = v.box({1, 1, 1});
  const std::vector<float> d = voxel_path_distance(box, {0, 0, 0});
  // (5, 3, 1): 1 step of sqrt(3), 2 of sqrt(2), 2 of 1.
  EXPECT_NEAR(d[box.box_index(5, 3, 1)], std::sqrt(3.0) + 2 * std::sqrt(2.0) + 2, 1e-5);
}

// Around a wall the path goes round it (longer than the straight line); voxels cut off stay unreached.
TEST(VoxelPath, PathGoesRoundAWallAndStopsAtDisconnectedVoxels) {
  Volume v({7, 5, 1});
  for (int j = 0; j < 4; ++j) v.at(3, j, 0) = 0;  // wall at i = 3 open only at j = 4
  v.at(6, 0, 0) = 1;
  const VoxelBox box = v.box({1, 1, 1});
  const std::vector<float> d = voxel_path_distance(box, {0, 0, 0});
  // Straight-line distance is 6; round the wall: up the diagonal to (3, 4), then down.
  EXPECT_GT(d[box.box_index(6, 0, 0)], 6.f + 1.f);
  EXPECT_NEAR(d[box.box_index(3, 4, 0)], 3 * std::sqrt(2.0) + 1, 1e-5);
  EXPECT_TRUE(std::isinf(d[box.box_index(3, 0, 0)]));  // a wall voxel
  Volume u({3, 1, 1});
  u.at(1, 0, 0) = 0;
  const VoxelBox ub = u.box({1, 1, 1});
  EXPECT_TRUE(std::isinf(voxel_path_distance(ub, {0, 0, 0})[ub.box_index(2, 0, 0)]));  // beyond a gap
}

// Only the sub-box is searched and the result is indexed by it: a way round through voxels outside the box is not taken.
TEST(VoxelPath, SearchStaysInsideTheSubBox) {
  Volume v({5, 3, 1});
  for (int j = 1; j < 3; ++j) v.at(2, j, 0) = 0;  // barrier in rows 1 and 2; row 0 goes round it
  VoxelBox box = v.box({1, 1, 1});
  const float whole = voxel_path_distance(box, {0, 1, 0})[box.box_index(4, 1, 0)];
  EXPECT_NEAR(whole, 2 * std::sqrt(2.0) + 2, 1e-5);  // (0,1) -> (1,0) -> (3,0) -> (4,1)
  box.lo = {0, 1, 0};                                 // rows 1..2 only
  const std::vector<float> d = voxel_path_distance(box, {0, 1, 0});
  EXPECT_EQ(d.size(), std::size_t(5 * 2));
  EXPECT_NEAR(d[box.box_index(1, 2, 0)], std::sqrt(2.0), 1e-5);
  EXPECT_TRUE(std::isinf(d[box.box_index(4, 1, 0)]));
}

}  // namespace
}  // namespace cf
