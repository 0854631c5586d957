// Tagged fluid in the crop: bright bodies (3 x 3 x 3 mean in [fluid-threshold, fluid-max]), their
// contacts with gas along each image axis, gravity from the level surfaces when the header does
// not give it, the pools kept (gas above them along one level) and the partial-volume layer.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "segment_internal.h"

namespace cf::segment_detail {
namespace {
constexpr unsigned char kGas = 1, kPool = 2, kLayer = 3, kCandidate = 4, kExcluded = 5;
}

void ColonSegmenter::find_fluid_bodies() {
  RunLabels fl;
  {
    Bytes bright(d_.total);
    const std::size_t plane = d_.n[0] * d_.n[1];
    box_mean3_slices(hu_.data(), d_, [&](std::size_t k, const float* mean) {  // noise spikes in soft tissue are not fluid
      for (std::size_t t = 0, q = k * plane; t < plane; ++t, ++q) {
        bright[q] = !lab_[q] && mean[t] >= opts_.fluid_threshold && mean[t] <= opts_.fluid_max;
        if (bright[q]) lab_[q] = kCandidate;
      }
    });
    fl = component_runs(bright.data(), d_);
  }
  fluid_count_ = fl.count();
  fluid_label_.assign(d_.total, 0);
  for (std::uint32_t l = 1; l <= fluid_count_; ++l)
    for (const Run* r = fl.begin(l); r != fl.end(l); ++r) std::fill_n(fluid_label_.data() + r->start, r->length, l);
  pool_.assign(fluid_count_ + 1, 0);
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

// Per fluid body and side (0: gas at lower index, 1: at higher index) along `axis`: the number of
// contact columns when they lie at one height (spread <= level-tolerance), else 0.
std::vector<std::array<std::size_t, 2>> ColonSegmenter::level_contacts(int axis) {
  Bytes contact(d_.total, 0);
  scan_contacts(axis, &contact, false);
  std::vector<std::vector<float>> heights[2];
  heights[0].resize(fluid_count_ + 1);
  heights[1].resize(fluid_count_ + 1);
  for (std::size_t q = 0; q < d_.total; ++q)
    if (contact[q]) {
      std::size_t c[3];
      d_.coords(q, c[0], c[1], c[2]);
      heights[contact[q] - 1][fluid_label_[q]].push_back(float(double(c[axis]) * d_.sp[axis]));
    }
  const double pixel_mm2 = d_.sp[0] * d_.sp[1] * d_.sp[2] / d_.sp[axis];
  const std::size_t min_columns = std::max<std::size_t>(8, std::size_t(std::ceil(100.0 / pixel_mm2)));  // 1 cm^2
  std::vector<std::array<std::size_t, 2>> out(fluid_count_ + 1, {0, 0});
  for (std::uint32_t l = 1; l <= fluid_count_; ++l)
    for (int side = 0; side < 2; ++side) {
      auto& v = heights[side][l];
      if (v.size() < min_columns) continue;
      std::sort(v.begin(), v.end());
      const double spread = v[v.size() * 9 / 10] - v[v.size() / 10];
      if (spread <= std::max(opts_.level_tolerance, 1.5 * d_.sp[axis])) out[l][side] = v.size();
    }
  return out;
}

// Gravity from the fluid levels: the axis and side with the largest level surface under gas.
void ColonSegmenter::gravity_from_levels() {
  double best_area = 0;
  int best_axis = -1, best_side = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const auto lv = level_contacts(axis);
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

// A fluid body is a pool when gas lies above it (against gravity) along a level surface; bone
// touching gas here and there has no level surface. Pools become lumen; other bodies stay candidates.
void ColonSegmenter::keep_level_pools() {
  const auto lv = level_contacts(grav_axis_);
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
}

void ColonSegmenter::mark_layer() { scan_contacts(grav_axis_, nullptr, true); }

}  // namespace cf::segment_detail
