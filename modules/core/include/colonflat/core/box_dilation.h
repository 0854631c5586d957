#pragma once
// Binary dilation of a voxel volume by a box (the maximum over [i - r, i + r] along each axis,
// clipped at the volume's faces: voxels outside count as background). Separable and exact; the
// rows, slices and lines are split over thread_count() threads, with the same result for any count.
#include <array>
#include <cstddef>

namespace cf {

// v, tmp: two buffers of n[0] * n[1] * n[2] bytes (x fastest); v holds the volume (any non-zero
// byte is set), tmp is scratch. r: half-widths along x, y, z in voxels (<= 0: that axis is
// skipped). Returns the buffer (v or tmp) that holds the dilated volume, as 0/1 bytes; the other
// buffer's contents are unspecified.
// With every r <= 0 nothing is done: v itself is returned, unchanged (not binarised). Pre: r[a] < 2^31.
unsigned char* dilate_box(unsigned char* v, unsigned char* tmp, const std::array<std::size_t, 3>& n, const int r[3]);

}  // namespace cf
