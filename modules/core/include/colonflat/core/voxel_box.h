#pragma once
// The box of the set voxels of a byte volume, in buffer indices (shared by reconstruct's crop and
// the report's CT planes, which map it to LPS).
#include <array>
#include <cstddef>

namespace cf {

// Inclusive bounding box of the non-zero voxels in buffer indices, and their count.
struct VoxelBox {
  std::array<std::size_t, 3> lo{0, 0, 0}, hi{0, 0, 0};
  std::size_t count = 0;
};

// d: n[0] * n[1] * n[2] bytes (x fastest); any non-zero byte is set. Slices are split over the
// threads (minima, maxima and the count do not depend on the split). No set voxel: count 0.
VoxelBox nonzero_box(const unsigned char* d, const std::array<std::size_t, 3>& n);

}  // namespace cf
