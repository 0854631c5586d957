#pragma once
// Shortest paths through a binary voxel volume: 26-neighbour Dijkstra with physical step lengths.
// Used wherever a lumen's course is measured from one voxel (the mask phantom's fully tagged
// stretches, the registration test pairs' cuts and polyps).
#include <array>
#include <cstddef>
#include <vector>

namespace cf {

// A voxel volume seen as a box: `mask` holds dims[0] * dims[1] * dims[2] bytes, x fastest; a voxel
// is inside when its byte is non-zero. The search runs over the sub-box [lo, hi) only.
struct VoxelBox {
  const unsigned char* mask = nullptr;
  std::array<int, 3> dims{0, 0, 0};
  std::array<double, 3> spacing{1, 1, 1};  // mm per voxel along i, j, k
  std::array<int, 3> lo{0, 0, 0}, hi{0, 0, 0};
  std::size_t box_size() const { return std::size_t(hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]); }
  // Index into a vector over the sub-box (i - lo, j - lo, k - lo; x fastest).
  std::size_t box_index(int i, int j, int k) const {
    return (std::size_t(k - lo[2]) * (hi[1] - lo[1]) + std::size_t(j - lo[1])) * (hi[0] - lo[0]) + std::size_t(i - lo[0]);
  }
};

// Path distance (mm) from voxel `start` (i, j, k; inside the box and the mask) to every voxel of
// the sub-box, through inside voxels only, moving to any of the 26 neighbours at the physical
// length of the step. Returns a vector of box.box_size() values indexed by box_index; +infinity
// where a voxel is outside the mask or not connected to `start`.
std::vector<float> voxel_path_distance(const VoxelBox& box, const std::array<int, 3>& start);

}  // namespace cf
