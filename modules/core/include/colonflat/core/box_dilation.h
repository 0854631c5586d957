#pragma once
// Binary dilation of a voxel volume by a box (the maximum over [i - r, i + r] along each axis,
// clipped at the volume's faces: voxels outside count as background). Separable and exact; the
// rows, slices and lines are split over thread_count() threads, with the same result for any count.
#include <array>
#include <cstddef>

namespace cf {

// v: n[0] * n[1] * n[2] bytes (x fastest), any non-zero byte set; dilated in place, left as 0/1
// bytes (no scratch volume: each pass keeps a voxel's own bit beside its result). r: half-widths
// along x, y, z in voxels (<= 0: that axis is skipped). With every r <= 0 nothing is done (v is
// not binarised). Pre: r[a] < 2^31.
void dilate_box(unsigned char* v, const std::array<std::size_t, 3>& n, const int r[3]);

}  // namespace cf
