// Gas bodies on the whole volume: threshold, face-connected components, outside air (lateral
// faces) and lungs (superior face) removed, a rectal tube's thin gas channel at the inferior face
// trimmed; then the crop around the remaining gas.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>

#include "colonflat/core/error.h"
#include "colonflat/core/params.h"
#include "segment_internal.h"

namespace cf::segment_detail {
namespace {
constexpr unsigned char kExcluded = 5;
}

void ColonSegmenter::find_gas_bodies() {
  MaskImage::Pointer work = mask_of_size(full_.n);
  unsigned char* w = work->GetBufferPointer();
  const float* fhu = ct_->GetBufferPointer();
  for (std::size_t q = 0; q < full_.total; ++q) w[q] = fhu[q] < opts_.air_threshold;
  std::uint32_t ngas = 0;
  LabelImage::Pointer gl = components(work, ngas);
  const std::uint32_t* glb = gl->GetBufferPointer();
  std::vector<BodyStats> bodies(ngas + 1);
  for (std::size_t k = 0, q = 0; k < full_.n[2]; ++k)
    for (std::size_t j = 0; j < full_.n[1]; ++j)
      for (std::size_t i = 0; i < full_.n[0]; ++i, ++q) {
        if (!glb[q]) continue;  // not gas (most of the volume)
        BodyStats& b = bodies[glb[q]];
        ++b.voxels;
        b.sum[0] += double(i), b.sum[1] += double(j), b.sum[2] += double(k);
      }
  std::vector<unsigned char> drop(ngas + 1, 0);  // 1 outside air, 2 lungs
  for (int a = 0; a < 3; ++a)
    for (int hi_side = 0; hi_side < 2; ++hi_side) {
      const bool superior = a == sup_axis_ && bool(hi_side) == sup_pos_;
      if (a == sup_axis_ && !superior) continue;  // the inferior face may hold the rectum
      std::size_t c[3];
      const std::size_t u = (a + 1) % 3, v = (a + 2) % 3;
      c[a] = hi_side ? full_.n[a] - 1 : 0;
      for (c[v] = 0; c[v] < full_.n[v]; ++c[v])
        for (c[u] = 0; c[u] < full_.n[u]; ++c[u]) {
          unsigned char& dr = drop[glb[full_.idx(c[0], c[1], c[2])]];
          if (!dr) dr = superior ? 2 : 1;
        }
    }
  for (std::uint32_t l = 1; l <= ngas; ++l) {
    if (!drop[l]) continue;
    ++st_.removed_components;
    const double c[3] = {bodies[l].sum[0] / double(bodies[l].voxels), bodies[l].sum[1] / double(bodies[l].voxels),
                         bodies[l].sum[2] / double(bodies[l].voxels)};
    decide("gas body", double(bodies[l].voxels) * voxel_ml_, c, false,
           drop[l] == 1 ? "outside air (touches a lateral face of the volume)" : "lungs (touch the superior face)");
  }
  drop[0] = 1;
  if (opts_.tube_area > 0) trim_rectal_tube(glb, drop, w);
  for (std::size_t q = 0; q < full_.total; ++q) w[q] = w[q] && !drop[glb[q]];
  gl = nullptr;
  lap("gas_components");
  crop_to_gas(w);
  lap("crop");
}

// Crop to the candidate gas plus a margin (fluid below the gas, the band, the tissue shell).
void ColonSegmenter::crop_to_gas(const unsigned char* gas) {
  std::size_t lo[3] = {full_.n[0], full_.n[1], full_.n[2]}, hi[3] = {0, 0, 0};
  std::size_t gas_vox = 0;
  for (std::size_t k = 0, q = 0; k < full_.n[2]; ++k)
    for (std::size_t j = 0; j < full_.n[1]; ++j)
      for (std::size_t i = 0; i < full_.n[0]; ++i, ++q) {
        if (!gas[q]) continue;
        ++gas_vox;
        lo[0] = std::min(lo[0], i), hi[0] = std::max(hi[0], i);
        lo[1] = std::min(lo[1], j), hi[1] = std::max(hi[1], j);
        lo[2] = std::min(lo[2], k), hi[2] = std::max(hi[2], k);
      }
  if (gas_vox == 0)
    throw PreconditionError("no colon found: no gas inside the body (below " + format_number(opts_.air_threshold) + " HU)");
  const double margin_mm = opts_.interface_width + opts_.band_width + 40.0;
  std::size_t cn[3];
  for (int a = 0; a < 3; ++a) {
    const std::size_t m = std::size_t(std::ceil(margin_mm / full_.sp[a]));
    blo_[a] = lo[a] > m ? lo[a] - m : 0;
    bhi_[a] = std::min(full_.n[a] - 1, hi[a] + m);
    cn[a] = bhi_[a] - blo_[a] + 1;
  }
  d_ = make_dims(cn, full_.sp);
  if (std::getenv("COLONFLAT_SEGMENT_DEBUG"))
    std::fprintf(stderr, "crop %zu x %zu x %zu of %zu x %zu x %zu\n", cn[0], cn[1], cn[2], full_.n[0], full_.n[1], full_.n[2]);
  lab_.assign(d_.total, 0);
  hu_.resize(d_.total);
  const float* fhu = ct_->GetBufferPointer();
  for (std::size_t k = 0; k < cn[2]; ++k)
    for (std::size_t j = 0; j < cn[1]; ++j) {
      const std::size_t from = full_.idx(blo_[0], blo_[1] + j, blo_[2] + k), to = (k * cn[1] + j) * cn[0];
      std::copy_n(gas + from, cn[0], lab_.data() + to);
      std::copy_n(fhu + from, cn[0], hu_.data() + to);
    }
  for (std::size_t q : tube_) {  // the rectal tube's channel and wall: never lumen
    std::size_t c[3];
    full_.coords(q, c[0], c[1], c[2]);
    if (c[0] < blo_[0] || c[1] < blo_[1] || c[2] < blo_[2] || c[0] > bhi_[0] || c[1] > bhi_[1] || c[2] > bhi_[2]) continue;
    lab_[d_.idx(c[0] - blo_[0], c[1] - blo_[1], c[2] - blo_[2])] = kExcluded;
  }
  std::vector<std::size_t>().swap(tube_);
}

}  // namespace cf::segment_detail
