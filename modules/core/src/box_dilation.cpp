// Binary dilation by a box, in place, separable: rows (axis 0) by doubling spans, axes 1 and 2 by
// the nearest set row before and after (moved here from segment's voxel grid so that segment and
// reconstruct share one implementation).
#include "colonflat/core/box_dilation.h"

#include <algorithm>
#include <cstdint>
#include <vector>

#include "colonflat/core/threads.h"

namespace cf {
namespace {
// Dilation along axis 0 (contiguous rows) of rows [row0, row1) of v, in place: v[i] = OR of
// v[i - r .. i + r]. Per row, a zero-padded copy where pass s ors each byte with the one 2^s ahead
// (then byte j covers 2^(s+1) bytes from j), until the span reaches half the window; two
// overlapping spans give each window. log2(2r + 1) + 2 branch-free byte passes, which the compiler
// vectorizes (the nearest-set scan before ran one voxel at a time).
void dilate_rows(unsigned char* v, std::size_t nx, std::size_t row0, std::size_t row1, long radius) {
  const std::size_t r = std::size_t(radius), w = 2 * r + 1, size = nx + 2 * r;
  std::vector<unsigned char> pad(size, 0);
  unsigned char* __restrict buf = pad.data();
  for (std::size_t row = row0; row < row1; ++row) {
    unsigned char* o = v + row * nx;
    for (std::size_t i = 0; i < nx; ++i) buf[r + i] = o[i] != 0;
    std::size_t span = 1;  // buf[j] = OR of the padded row's [j, j + span)
    for (; 2 * span <= w; span *= 2)
      for (std::size_t j = 0; j + span < size; ++j) buf[j] |= buf[j + span];
    for (std::size_t i = 0; i < nx; ++i) o[i] = buf[i] | buf[i + w - span];
    std::fill_n(buf, r, 0), std::fill_n(buf + r + nx, r, 0);  // the padding for the next row
  }
}

// The two sweeps of a line dilation, in place: the forward sweep keeps each voxel's own bit as
// bit 1 (kSet) beside its forward hit in bit 0, the backward sweep reads that bit and leaves 0/1.
constexpr unsigned char kSet = 2;

// One row of dilate_across_bytes: dist (rows since the nearest set row, saturating at 255) steps on
// by one row. Byte lanes with no branch and no aliasing, so the compiler vectorizes it (the int32
// form below ran one voxel at a time).
template <bool kBackward>
void across_row(unsigned char* __restrict o, unsigned char* __restrict dist, std::size_t nx, unsigned char radius) {
  for (std::size_t i = 0; i < nx; ++i) {
    const bool set = kBackward ? (o[i] & kSet) != 0 : o[i] != 0;
    const unsigned char n = set ? 0 : static_cast<unsigned char>(dist[i] + (dist[i] < 255));
    dist[i] = n;
    const unsigned char hit = n <= radius;
    o[i] = kBackward ? static_cast<unsigned char>((o[i] & 1) | hit) : static_cast<unsigned char>((set ? kSet : 0) | hit);
  }
}

// dilate_across for radius < 255: the same result from byte distances.
void dilate_across_bytes(unsigned char* v, std::size_t nx, std::size_t base, std::size_t step, std::size_t count,
                         unsigned char radius, std::vector<unsigned char>& dist) {
  dist.assign(nx, 255);
  for (std::size_t t = 0; t < count; ++t) across_row<false>(v + base + t * step, dist.data(), nx, radius);
  dist.assign(nx, 255);
  for (std::size_t t = count; t-- > 0;) across_row<true>(v + base + t * step, dist.data(), nx, radius);
}

// Dilation along a line of `count` rows `step` bytes apart (rows of nx bytes) starting at `base`,
// in place: per x, the nearest set row before and after each row (two sweeps, O(1) per voxel).
void dilate_across(unsigned char* v, std::size_t nx, std::size_t base, std::size_t step, std::size_t count, long radius,
                   std::vector<std::int32_t>& near) {
  if (radius < 255) {
    std::vector<unsigned char> dist;
    return dilate_across_bytes(v, nx, base, step, count, static_cast<unsigned char>(radius), dist);
  }
  near.assign(nx, -1000000);
  for (std::size_t t = 0; t < count; ++t) {
    unsigned char* o = v + base + t * step;
    const std::int32_t pos = std::int32_t(t);
    for (std::size_t i = 0; i < nx; ++i) {
      const bool set = o[i] != 0;
      near[i] = set ? pos : near[i];
      o[i] = static_cast<unsigned char>((set ? kSet : 0) | (pos - near[i] <= radius));
    }
  }
  near.assign(nx, 1000000);
  for (std::size_t t = count; t-- > 0;) {
    unsigned char* o = v + base + t * step;
    const std::int32_t pos = std::int32_t(t);
    for (std::size_t i = 0; i < nx; ++i) {
      near[i] = (o[i] & kSet) ? pos : near[i];
      o[i] = static_cast<unsigned char>((o[i] & 1) | (near[i] - pos <= radius));
    }
  }
}
}  // namespace

void dilate_box(unsigned char* v, const std::array<std::size_t, 3>& n, const int r[3]) {
  const std::size_t nx = n[0], ny = n[1], nz = n[2];
  for (int ax = 0; ax < 3; ++ax) {
    if (r[ax] <= 0) continue;
    const long radius = r[ax];
    if (ax == 0) {
      parallel_for(ny * nz, [&](std::size_t r0, std::size_t r1) { dilate_rows(v, nx, r0, r1, radius); });
    } else if (ax == 1) {  // lines along y: one per slice
      parallel_for(nz, [&](std::size_t k0, std::size_t k1) {
        std::vector<std::int32_t> near;
        for (std::size_t k = k0; k < k1; ++k) dilate_across(v, nx, k * nx * ny, nx, ny, radius, near);
      });
    } else {  // lines along z: one per row index j
      parallel_for(ny, [&](std::size_t j0, std::size_t j1) {
        std::vector<std::int32_t> near;
        for (std::size_t j = j0; j < j1; ++j) dilate_across(v, nx, j * nx, nx * ny, nz, radius, near);
      });
    }
  }
}

}  // namespace cf
