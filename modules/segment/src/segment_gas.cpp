// Gas bodies on the whole volume: threshold, face-connected components, outside air (lateral
// faces) and lungs (superior face) removed, a rectal tube's thin gas channel at the inferior face
// trimmed; then the crop around the remaining gas.
#include <algorithm>
#include <cmath>
#include <set>

#include "colonflat/core/error.h"
#include "colonflat/core/params.h"
#include "segment_internal.h"

namespace cf::segment_detail {

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
  if (opts_.tube_area > 0) trim_rectal_tube(glb, ngas, drop, w);
  for (std::size_t q = 0; q < full_.total; ++q) w[q] = w[q] && !drop[glb[q]];
  gl = nullptr;
  lap("gas_components");
  crop_to_gas(w);
  lap("crop");
}

// A gas body reaching the inferior face through a channel thinner than tube-area (a rectal tube's
// air lumen, an anal canal) loses the slices of that channel, from the face up to the first slice
// where its cross-section reaches tube-area (the rectum).
void ColonSegmenter::trim_rectal_tube(const std::uint32_t* glb, std::uint32_t ngas, std::vector<unsigned char>& drop,
                                      unsigned char* gas) {
  const std::size_t ns = full_.n[sup_axis_];
  // Visits every voxel with its slice number counted from the inferior face.
  auto for_each_voxel = [&](const std::function<void(std::size_t, const std::size_t*, std::size_t)>& f) {
    std::size_t c[3], q = 0;
    for (c[2] = 0; c[2] < full_.n[2]; ++c[2])
      for (c[1] = 0; c[1] < full_.n[1]; ++c[1])
        for (c[0] = 0; c[0] < full_.n[0]; ++c[0], ++q)
          if (glb[q]) f(q, c, sup_pos_ ? c[sup_axis_] : ns - 1 - c[sup_axis_]);
  };
  std::vector<std::vector<std::size_t>> area(ngas + 1);
  {
    std::size_t c[3];
    const std::size_t u = (sup_axis_ + 1) % 3, v = (sup_axis_ + 2) % 3;
    c[sup_axis_] = sup_pos_ ? 0 : ns - 1;
    for (c[v] = 0; c[v] < full_.n[v]; ++c[v])
      for (c[u] = 0; c[u] < full_.n[u]; ++c[u]) {
        const std::uint32_t l = glb[full_.idx(c[0], c[1], c[2])];
        if (!drop[l] && area[l].empty()) area[l].assign(ns, 0);
      }
  }
  for_each_voxel([&](std::size_t q, const std::size_t*, std::size_t s) {
    if (!area[glb[q]].empty()) ++area[glb[q]][s];
  });
  double pixel_mm2 = 1;
  for (int a = 0; a < 3; ++a)
    if (a != sup_axis_) pixel_mm2 *= full_.sp[a];
  std::vector<std::size_t> cut(ngas + 1, 0);  // slices [0, cut) are trimmed
  for (std::uint32_t l = 1; l <= ngas; ++l) {
    if (area[l].empty()) continue;
    std::size_t s = 0;
    while (s < ns && double(area[l][s]) * pixel_mm2 < opts_.tube_area) ++s;
    cut[l] = s;
  }
  std::size_t trimmed = 0;
  double sum[3] = {0, 0, 0};
  for_each_voxel([&](std::size_t q, const std::size_t* c, std::size_t s) {
    if (!gas[q] || s >= cut[glb[q]]) return;  // sum: coordinate sums of the trimmed voxels
    gas[q] = 0;
    ++trimmed;
    for (int a = 0; a < 3; ++a) sum[a] += double(c[a]);
  });
  if (trimmed == 0) return;
  for (std::uint32_t l = 1; l <= ngas; ++l)
    if (cut[l] > 0 && cut[l] < ns) trimmed += follow_tube_lumen(glb, l, cut[l], gas, sum);
  st_.rectal_tube_trimmed_ml = double(trimmed) * voxel_ml_;
  for (double& v : sum) v /= double(trimmed);
  decide("gas channel", st_.rectal_tube_trimmed_ml, sum, false,
         "rectal tube / anal canal: thinner than --tube-area from the inferior face up to the rectum");
}

// Above the trimmed channel the catheter's air lumen runs on inside the rectum, walled off from the
// rectal gas by the plastic: slice by slice, the in-plane gas component over the previous slice's
// trimmed voxels is trimmed while it stays thinner than tube-area. Returns the voxels trimmed.
std::size_t ColonSegmenter::follow_tube_lumen(const std::uint32_t* glb, std::uint32_t label, std::size_t first_slice,
                                              unsigned char* gas, double sum[3]) {
  const int u = (sup_axis_ + 1) % 3, v = (sup_axis_ + 2) % 3;
  const std::size_t ns = full_.n[sup_axis_];
  double pixel_mm2 = full_.sp[u] * full_.sp[v];
  auto index = [&](std::size_t s, std::size_t a, std::size_t b) {
    std::size_t c[3];
    c[sup_axis_] = sup_pos_ ? s : ns - 1 - s;
    c[u] = a;
    c[v] = b;
    return full_.idx(c[0], c[1], c[2]);
  };
  std::vector<std::pair<std::size_t, std::size_t>> prev;  // trimmed (a, b) of the slice below
  for (std::size_t a = 0; a < full_.n[u]; ++a)
    for (std::size_t b = 0; b < full_.n[v]; ++b)
      if (glb[index(first_slice - 1, a, b)] == label) prev.emplace_back(a, b);
  std::size_t trimmed = 0;
  for (std::size_t s = first_slice; s < ns && !prev.empty(); ++s) {
    std::vector<std::pair<std::size_t, std::size_t>> comp, stack;
    for (const auto& p : prev)
      if (gas[index(s, p.first, p.second)] && glb[index(s, p.first, p.second)] == label) stack.push_back(p);
    std::set<std::pair<std::size_t, std::size_t>> visited(stack.begin(), stack.end());
    while (!stack.empty() && double(comp.size()) * pixel_mm2 < opts_.tube_area) {
      const auto p = stack.back();
      stack.pop_back();
      comp.push_back(p);
      const long da[4] = {-1, 1, 0, 0}, db[4] = {0, 0, -1, 1};
      for (int t = 0; t < 4; ++t) {
        const long a = long(p.first) + da[t], b = long(p.second) + db[t];
        if (a < 0 || b < 0 || a >= long(full_.n[u]) || b >= long(full_.n[v])) continue;
        const std::size_t q = index(s, std::size_t(a), std::size_t(b));
        if (gas[q] && glb[q] == label && visited.insert({std::size_t(a), std::size_t(b)}).second)
          stack.emplace_back(std::size_t(a), std::size_t(b));
      }
    }
    if (comp.empty() || double(comp.size()) * pixel_mm2 >= opts_.tube_area) break;  // the tube's tip: rectal gas
    for (const auto& p : comp) {
      const std::size_t q = index(s, p.first, p.second);
      gas[q] = 0;
      std::size_t c[3];
      full_.coords(q, c[0], c[1], c[2]);
      for (int k = 0; k < 3; ++k) sum[k] += double(c[k]);
    }
    trimmed += comp.size();
    prev.swap(comp);
  }
  return trimmed;
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
  hu_.resize(d_.total);
  const float* fhu = ct_->GetBufferPointer();
  for (std::size_t k = 0; k < cn[2]; ++k)
    for (std::size_t j = 0; j < cn[1]; ++j) {
      const std::size_t from = full_.idx(blo_[0], blo_[1] + j, blo_[2] + k), to = (k * cn[1] + j) * cn[0];
      std::copy_n(gas + from, cn[0], lab_.data() + to);
      std::copy_n(fhu + from, cn[0], hu_.data() + to);
    }
}

}  // namespace cf::segment_detail
