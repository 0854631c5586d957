// Gas bodies on the whole volume: threshold, face-connected components, outside air (lateral
// faces) and lungs (superior face) removed, a rectal tube's thin gas channel at the inferior face
// trimmed; then the crop around the remaining gas.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <vector>

#include "colonflat/core/error.h"
#include "colonflat/core/params.h"
#include "segment_internal.h"

namespace cf::segment_detail {
namespace {
constexpr unsigned char kExcluded = 5;
}

void ColonSegmenter::find_gas_bodies() {
  Bytes gas(full_.total);
  const float* fhu = ct_->GetBufferPointer();
  parallel_for(full_.total, [&](std::size_t q0, std::size_t q1) {
    for (std::size_t q = q0; q < q1; ++q) gas[q] = fhu[q] < opts_.air_threshold;
  });
  const RunLabels gl = component_runs(gas.data(), full_);
  const std::vector<unsigned char> drop = outside_gas(gl);
  if (opts_.tube_area > 0) trim_rectal_tube(inferior_face_dropped(gl, drop), gas.data());
  for (std::uint32_t l = 1; l <= gl.count(); ++l)
    if (drop[l])
      for (const Run* r = gl.begin(l); r != gl.end(l); ++r) std::fill_n(gas.data() + r->start, r->length, 0);
  lap("gas_components");
  step_time("gas bodies");
  crop_to_gas(gas.data());
  lap("crop");
}

// Per gas body: 1 outside air (touches a lateral face of the volume), 2 lungs (the superior face),
// 0 kept (the inferior face may hold the rectum). A body touching several faces gets the code of
// the first in the order x-, x+, y-, y+, z-, z+. Removed bodies are reported.
std::vector<unsigned char> ColonSegmenter::outside_gas(const RunLabels& gl) {
  std::vector<unsigned char> drop(gl.count() + 1, 0);
  for (std::uint32_t l = 1; l <= gl.count(); ++l) {
    double sum[3] = {0, 0, 0}, voxels = 0;
    unsigned faces = 0;  // bit 2 a + hi_side
    for (const Run* r = gl.begin(l); r != gl.end(l); ++r) {
      std::size_t c[3];
      full_.coords(r->start, c[0], c[1], c[2]);
      const double len = double(r->length);
      voxels += len;
      sum[0] += len * double(c[0]) + len * (len - 1) / 2;
      sum[1] += len * double(c[1]), sum[2] += len * double(c[2]);
      faces |= (c[0] == 0 ? 1u : 0u) | (c[0] + r->length == full_.n[0] ? 2u : 0u);
      for (int a = 1; a < 3; ++a) faces |= (c[a] == 0 ? 1u << (2 * a) : 0u) | (c[a] + 1 == full_.n[a] ? 2u << (2 * a) : 0u);
    }
    for (int a = 0; a < 3 && !drop[l]; ++a)
      for (int hi_side = 0; hi_side < 2 && !drop[l]; ++hi_side) {
        const bool superior = a == sup_axis_ && bool(hi_side) == sup_pos_;
        if ((a == sup_axis_ && !superior) || !(faces & (1u << (2 * a + hi_side)))) continue;
        drop[l] = superior ? 2 : 1;
      }
    if (!drop[l]) continue;
    ++st_.removed_components;
    const double c[3] = {sum[0] / voxels, sum[1] / voxels, sum[2] / voxels};
    decide("gas body", voxels * voxel_ml_, c, false,
           drop[l] == 1 ? "outside air (touches a lateral face of the volume)" : "lungs (touch the superior face)");
  }
  return drop;
}

// The pixels of the inferior face slice (in-plane index b * n[u] + a, as slice_index) that belong
// to a removed gas body.
std::vector<unsigned char> ColonSegmenter::inferior_face_dropped(const RunLabels& gl, const std::vector<unsigned char>& drop) const {
  const int u = (sup_axis_ + 1) % 3, v = (sup_axis_ + 2) % 3;
  const std::size_t face = sup_pos_ ? 0 : full_.n[sup_axis_] - 1;
  std::vector<unsigned char> out(full_.n[u] * full_.n[v], 0);
  for (std::uint32_t l = 1; l <= gl.count(); ++l) {
    if (!drop[l]) continue;
    for (const Run* r = gl.begin(l); r != gl.end(l); ++r) {
      std::size_t c[3];
      full_.coords(r->start, c[0], c[1], c[2]);
      for (std::size_t i = c[0]; i < c[0] + r->length; ++i) {
        const std::size_t at[3] = {i, c[1], c[2]};
        if (at[sup_axis_] == face) out[at[v] * full_.n[u] + at[u]] = 1;
      }
    }
  }
  return out;
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
  lab_.assign(d_.total, 0);
  const auto row_start = [&](std::size_t r) { return full_.idx(blo_[0], blo_[1] + r % cn[1], blo_[2] + r / cn[1]); };
  parallel_for(cn[1] * cn[2], [&](std::size_t r0, std::size_t r1) {
    for (std::size_t r = r0; r < r1; ++r) std::copy_n(gas + row_start(r), cn[0], lab_.data() + r * cn[0]);
  });
  hu_.copy(ct_->GetBufferPointer(), cn[1] * cn[2], cn[0], row_start);
  if (std::getenv("COLONFLAT_SEGMENT_DEBUG"))
    std::fprintf(stderr, "crop %zu x %zu x %zu of %zu x %zu x %zu, HU in %s\n", cn[0], cn[1], cn[2], full_.n[0], full_.n[1],
                 full_.n[2], hu_.narrow() ? "16 bits" : "float");
  for (std::size_t q : tube_) {  // the rectal tube's channel and wall: never lumen
    std::size_t c[3];
    full_.coords(q, c[0], c[1], c[2]);
    if (c[0] < blo_[0] || c[1] < blo_[1] || c[2] < blo_[2] || c[0] > bhi_[0] || c[1] > bhi_[1] || c[2] > bhi_[2]) continue;
    lab_[d_.idx(c[0] - blo_[0], c[1] - blo_[1], c[2] - blo_[2])] = kExcluded;
  }
  std::vector<std::size_t>().swap(tube_);
}

}  // namespace cf::segment_detail
