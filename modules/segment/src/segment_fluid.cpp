// Tagged fluid in the crop: bright bodies (3 x 3 x 3 mean in [fluid-threshold, fluid-max]), their
// contacts with gas along each image axis, gravity from the level surfaces when the header does
// not give it, the pools kept (gas above them along one level) and the partial-volume layer.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <mutex>
#include <utility>
#include <sstream>

#include "segment_internal.h"

namespace cf::segment_detail {
namespace {
constexpr unsigned char kGas = 1, kPool = 2, kLayer = 3, kCandidate = 4, kExcluded = 5;
}

// Bright voxels (3 x 3 x 3 mean in [fluid-threshold, fluid-max]) split into one piece per lumen
// (segment_split.cpp), and the gas components of the crop for the level test.
void ColonSegmenter::find_fluid_bodies() {
  Bytes bright(d_.total);
  const std::size_t plane = d_.n[0] * d_.n[1];
  box_mean3_slices(hu_, d_, [&](std::size_t k, const float* mean) {  // noise spikes in soft tissue are not fluid
    for (std::size_t t = 0, q = k * plane; t < plane; ++t, ++q) {
      bright[q] = !lab_[q] && mean[t] >= opts_.fluid_threshold && mean[t] <= opts_.fluid_max;
      if (bright[q]) lab_[q] = kCandidate;
    }
  });
  step_time("bright");
  split_fluid_bodies(bright);
  step_time("split_fluid_bodies");
  pool_.assign(fluid_count_ + 1, 0);
  Bytes gas(d_.total);
  for_each_voxel(d_.total, [&](std::size_t q) { gas[q] = lab_[q] == kGas; });
  const RunLabels gl = component_runs(gas.data(), d_);
  gas_voxels_.assign(gl.count() + 1, 0);
  for (std::uint32_t l = 1; l <= gl.count(); ++l)
    for (const Run* r = gl.begin(l); r != gl.end(l); ++r) gas_voxels_[l] += r->length;
  gas_lookup_ = RunLookup(gl);
}

// Scans every line along `axis` for gas and fluid at most interface-width apart. contact: 1 where
// a fluid voxel has gas on its lower-index side, 2 on its higher-index side (candidates). With
// `layer`, the voxels between gas and kept pools become layer.
void ColonSegmenter::scan_contacts(int axis, Bytes* contact, bool layer) {
  const int wvox = int(std::ceil(opts_.interface_width / d_.sp[axis]));
  const std::size_t stride = d_.stride[axis], len = d_.n[axis];
  const unsigned char fluid = layer ? kPool : kCandidate;
  parallel_for(d_.total / len, [&](std::size_t l0, std::size_t l1) {
    for (std::size_t l = l0; l < l1; ++l) {
      const std::size_t base = line_base(d_, axis, l);
      int last_kind = 0, last_pos = -1000000;
      for (int p = 0; p < int(len); ++p) {
        const std::size_t q = base + std::size_t(p) * stride;
        const unsigned char k = lab_[q] == kGas ? 1 : (lab_[q] == fluid ? 2 : 0);
        if (!k) continue;
        if (last_kind && last_kind != k && p - last_pos - 1 <= wvox) {
          if (layer)
            for (int r = last_pos + 1; r < p; ++r)
              if (lab_[base + std::size_t(r) * stride] != kExcluded) lab_[base + std::size_t(r) * stride] = kLayer;
          if (contact) {
            if (k == 2) (*contact)[q] = 1;  // gas at lower index, fluid here
            else (*contact)[base + std::size_t(last_pos) * stride] = 2;
          }
        }
        last_kind = k;
        last_pos = p;
      }
    }
  });
}

namespace {
// Adds the height of each contact voxel of z-slices [k0, k1) to h[side][(fluid piece, gas body)].
void gather_slab(const LevelGatherInput& in, std::size_t k0, std::size_t k1, LevelHeights h[2]) {
  const Dims& d = *in.d;
  const std::size_t stride = d.stride[in.axis];
  for (std::size_t q = k0 * d.n[0] * d.n[1], end = k1 * d.n[0] * d.n[1]; q < end; ++q) {
    if (!in.contact[q]) continue;
    std::size_t c[3];
    d.coords(q, c[0], c[1], c[2]);
    const int side = in.contact[q] - 1;
    std::uint32_t g = 0;  // the gas voxel the contact faces, at most interface-width + 1 voxels away
    for (long t = 1; t <= in.wvox + 1 && !g; ++t) {
      const long p = side == 0 ? long(c[in.axis]) - t : long(c[in.axis]) + t;
      if (p < 0 || p >= long(d.n[in.axis])) break;
      const std::size_t r = side == 0 ? q - std::size_t(t) * stride : q + std::size_t(t) * stride;
      if (in.lab[r] == kGas) g = in.gas->at(r);
    }
    h[side][{in.fluid_label[q], g}].push_back(float(double(c[in.axis]) * d.sp[in.axis]));
  }
}
}  // namespace

std::size_t gather_level_heights(const LevelGatherInput& in, LevelHeights heights[2]) {
  std::mutex mu;
  std::vector<std::pair<std::size_t, std::array<LevelHeights, 2>>> slabs;  // (first slice, its heights)
  parallel_for(in.d->n[2], [&](std::size_t k0, std::size_t k1) {
    std::array<LevelHeights, 2> h;
    gather_slab(in, k0, k1, h.data());
    std::lock_guard<std::mutex> lock(mu);
    slabs.emplace_back(k0, std::move(h));
  });
  std::sort(slabs.begin(), slabs.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (auto& slab : slabs)  // in z order: each list as the serial raster scan gives it
    for (int side = 0; side < 2; ++side)
      for (auto& [key, v] : slab.second[side]) {
        std::vector<float>& dst = heights[side][key];
        dst.insert(dst.end(), v.begin(), v.end());
      }
  return slabs.size();
}

// Per fluid body and side (0: gas at lower index, 1: at higher index) along `axis`: the number of
// contact columns it shares with gas bodies along which they lie at one height (per gas body: a
// gas body and a fluid body in one lumen meet at one level, since each has one pressure; one fluid
// body may meet several gas bodies at different heights). A pair counts when its contacts cover
// >= 1 cm^2 and their heights spread (10th-90th percentile) <= level-tolerance, and the gas body
// holds at least min_gas_voxels.
std::vector<std::array<std::size_t, 2>> ColonSegmenter::level_contacts(int axis, std::size_t min_gas_voxels) {
  Bytes contact(d_.total, 0);
  scan_contacts(axis, &contact, false);
  const LevelGatherInput in{&d_, axis, int(std::ceil(opts_.interface_width / d_.sp[axis])), contact.data(), lab_.data(),
                            fluid_label_.data(), &gas_lookup_};
  LevelHeights heights[2];  // (fluid, gas) -> heights
  gather_level_heights(in, heights);
  const double pixel_mm2 = d_.sp[0] * d_.sp[1] * d_.sp[2] / d_.sp[axis];
  const std::size_t min_columns = std::max<std::size_t>(8, std::size_t(std::ceil(100.0 / pixel_mm2)));  // 1 cm^2
  std::vector<std::array<std::size_t, 2>> out(fluid_count_ + 1, {0, 0});
  for (int side = 0; side < 2; ++side)
    for (auto& [key, v] : heights[side]) {
      if (v.size() < min_columns || gas_voxels_[key.second] < min_gas_voxels) continue;
      std::sort(v.begin(), v.end());
      const double spread = v[v.size() * 9 / 10] - v[v.size() / 10];
      if (spread <= std::max(opts_.level_tolerance, 1.5 * d_.sp[axis])) out[key.first][side] += v.size();
    }
  return out;
}

// Gravity from the fluid levels: the axis and side with the largest level surface under gas.
void ColonSegmenter::gravity_from_levels() {
  double best_area = 0;
  int best_axis = -1, best_side = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const auto lv = level_contacts(axis, 0);  // any gas: small-bowel bubbles show gravity too
    const double pixel_mm2 = d_.sp[0] * d_.sp[1] * d_.sp[2] / d_.sp[axis];
    for (int side = 0; side < 2; ++side) {
      double area = 0;
      for (const auto& c : lv) area += double(c[side]) * pixel_mm2;
      if (area > best_area) best_area = area, best_axis = axis, best_side = side;
    }
  }
  gravity_known_ = true;
  if (best_axis < 0) {  // no level anywhere: the usual supine scan (posterior down)
    const auto D = ct_->GetDirection();
    grav_axis_ = 0;
    for (int a = 1; a < 3; ++a)
      if (std::abs(D[1][a]) > std::abs(D[1][grav_axis_])) grav_axis_ = a;
    grav_sign_ = D[1][grav_axis_] > 0 ? 1 : -1;
    gravity_source_ = "default (supine): no PatientPosition and no fluid level";
    return;
  }
  grav_axis_ = best_axis;
  grav_sign_ = best_side == 0 ? 1 : -1;  // gas at lower index above the fluid: gravity towards +index
  std::ostringstream s;
  s << "fluid levels (" << std::lround(best_area / 100.0) << " cm^2 of level surface under gas)";
  gravity_source_ = gravity_source_.empty() ? s.str() : gravity_source_ + "; " + s.str();
}

// A fluid piece is a pool when insufflated colon gas (a gas body of at least min-segment-volume)
// lies above it (against gravity) along a level surface; bone touching gas here and there has no
// level surface, and small bowel holds only small bubbles of swallowed gas. Pools become lumen;
// other pieces stay candidates.
void ColonSegmenter::keep_level_pools() {
  const auto lv = level_contacts(grav_axis_, std::size_t(std::ceil(opts_.min_segment_volume / voxel_ml_)));
  const int side = grav_sign_ > 0 ? 0 : 1;
  for (std::uint32_t l = 1; l <= fluid_count_; ++l) pool_[l] = lv[l][side] > 0;
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t q = 0; q < d_.total; ++q)
    if (lab_[q] == kCandidate && pool_[fluid_label_[q]]) {
      lab_[q] = kPool;
      sum += hu_[q];
      ++n;
    }
  st_.fluid_hu = n ? sum / double(n) : 0.0;
  if (std::getenv("COLONFLAT_SEGMENT_DEBUG")) debug_pieces(lv, side);
}

// Every fluid piece of >= 3 mL: volume, centroid (LPS), mean HU, level contacts, pool or not.
void ColonSegmenter::debug_pieces(const std::vector<std::array<std::size_t, 2>>& lv, int side) const {
  std::vector<std::array<double, 5>> acc(fluid_count_ + 1, {0, 0, 0, 0, 0});
  for (std::size_t q = 0; q < d_.total; ++q) {
    const std::uint32_t l = fluid_label_[q];
    if (!l) continue;
    std::size_t c[3];
    d_.coords(q, c[0], c[1], c[2]);
    acc[l][0] += 1, acc[l][1] += double(c[0]), acc[l][2] += double(c[1]), acc[l][3] += double(c[2]), acc[l][4] += hu_[q];
  }
  for (std::uint32_t l = 1; l <= fluid_count_; ++l) {
    const double n = acc[l][0];
    if (n * voxel_ml_ < 3) continue;
    const double c[3] = {acc[l][1] / n, acc[l][2] / n, acc[l][3] / n};
    const auto p = lps_of(c);
    std::fprintf(stderr, "piece %u %.1f mL at LPS (%.0f %.0f %.0f) crop (%.0f %.0f %.0f) HU %.0f level %zu %s\n", l, n * voxel_ml_, p[0], p[1], p[2],
                 c[0], c[1], c[2], acc[l][4] / n, lv[l][side], pool_[l] ? "POOL" : "-");
  }
}

void ColonSegmenter::mark_layer() { scan_contacts(grav_axis_, nullptr, true); }

}  // namespace cf::segment_detail
