#pragma once
// The grid of an nx x ny x nz volume of 1 mm voxels, for the segmentation's internal tests.
#include <cstddef>

#include "../src/segment_internal.h"

namespace cf::segment_detail {

inline Dims unit_dims(std::size_t nx, std::size_t ny, std::size_t nz) {
  const std::size_t n[3] = {nx, ny, nz};
  const double sp[3] = {1, 1, 1};
  return make_dims(n, sp);
}

}  // namespace cf::segment_detail
