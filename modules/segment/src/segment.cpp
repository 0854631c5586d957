// segment_colon: the steps of ColonSegmenter (docs/segment.md) that run on the whole volume (checks,
// gravity from the header, gas bodies, rectal tube, crop) and after the lumen is chosen (class
// means, graph cut, final segments, paste). Tagged fluid: segment_fluid.cpp; segment choice and
// fully tagged stretches: segment_link.cpp; graph cut: segment_graphcut.cpp.
#include "colonflat/segment/segment.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <tuple>
#include <map>
#include <mutex>
#include <numeric>
#include <sstream>

#include <sys/resource.h>

#include "colonflat/core/error.h"
#include "colonflat/core/progress.h"
#include "colonflat/core/params.h"
#include "segment_internal.h"

namespace cf {

nlohmann::json SegmentStats::to_json() const {
  nlohmann::json j = {{"segments", segments},
          {"segment_volumes_ml", segment_volumes_ml},
          {"lumen_volume_ml", lumen_volume_ml},
          {"fluid_volume_ml", fluid_volume_ml},
          {"class_means_hu", {{"air", air_hu}, {"tissue", tissue_hu}, {"fluid", fluid_hu}}},
          {"gravity", gravity},
          {"gravity_source", gravity_source},
          {"tagged_stretches", tagged_stretches},
          {"tagged_stretch_volume_ml", tagged_stretch_volume_ml},
          {"rectal_tube_trimmed_ml", rectal_tube_trimmed_ml},
          {"band_voxels", band_voxels},
          {"graph_edges", graph_edges},
          {"max_flow", flow},
          {"removed_components", removed_components},
          {"rejected_fluid_components", rejected_fluid_components},
          {"decision_counts", decision_counts},
          {"decisions", decisions},
          {"time_s", time_s},
          {"graph_cut_time_s", graph_cut_time_s},
          {"peak_memory_mib", peak_memory_mib},
          {"timings_s", timings},
          {"cpu_time_s", cpu_time_s},
          {"cpu_timings_s", cpu_timings}};
  if (!links.empty()) j["links"] = links;
  return j;
}

void validate(const SegmentOptions& o) {
  segment_param_table().validate(o);  // each parameter's range and choices
  if (!(o.fluid_max > o.fluid_threshold))
    throw UsageError("--fluid-max must be above --fluid-threshold (got " + format_number(o.fluid_max) + " <= " +
                     format_number(o.fluid_threshold) + ")");
}

MaskImage::Pointer segment_colon(const CtImage* ct, const SegmentOptions& opts, SegmentStats* stats_out,
                                 const std::function<void()>& voxels_read) {
  validate(opts);
  if (!ct) throw PreconditionError("segment: no volume");
  return segment_detail::ColonSegmenter(ct, opts, voxels_read).run(stats_out);
}

namespace segment_detail {

MaskImage::Pointer ColonSegmenter::run(SegmentStats* stats) {
  cpu_start_ = cpu_lap_ = process_cpu_seconds();
  check_input();
  gravity_from_metadata();
  lap("checks");
  step_time("checks");  // starts the sub-step clock
  find_gas_bodies();
  release_ct_voxels();
  step_time("crop");
  find_fluid_bodies();
  step_time("find_fluid_bodies");
  if (!gravity_known_) gravity_from_levels();
  step_time("gravity_from_levels");
  keep_level_pools();
  step_time("keep_level_pools");
  mark_layer();
  step_time("mark_layer");
  lap("tagged_fluid");
  select_segments();
  step_time("select_segments");
  link_tagged_stretches();
  step_time("link_tagged_stretches");
  lap("segments");
  class_means();
  lap("class_means");
  step_time("class_means");
  refine_boundary();
  step_time("refine_boundary");
  lap("graph_cut");
  final_segments();
  step_time("final_segments");
  MaskImage::Pointer out = paste();
  lap("final_segments");
  st_.time_s = clock_.seconds();
  st_.cpu_time_s = process_cpu_seconds() - cpu_start_;
  st_.cpu_timings = cpu_timings_;
  st_.peak_memory_mib = peak_memory_mib();
  st_.timings = timings_;
  st_.gravity_source = gravity_source_;
  static const char* names[3][2] = {{"-x (right)", "+x (left)"}, {"-y (anterior)", "+y (posterior)"}, {"-z (inferior)", "+z (superior)"}};
  const auto D = ct_->GetDirection();  // gravity in LPS: the image axis' direction times its sign
  int lps = 0;
  for (int a = 1; a < 3; ++a)
    if (std::abs(D[a][grav_axis_]) > std::abs(D[lps][grav_axis_])) lps = a;
  st_.gravity = names[lps][D[lps][grav_axis_] * grav_sign_ > 0 ? 1 : 0];
  summarize_decisions();
  st_.links = link_log_;
  if (stats) *stats = st_;
  return out;
}

void ColonSegmenter::lap(const char* name) {
  timings_[name] = step_.seconds();
  step_.restart();
  const double cpu = process_cpu_seconds();
  cpu_timings_[name] = cpu - cpu_lap_;
  cpu_lap_ = cpu;
  phase_done(name);
}

// From the crop on only the crop's own copy (hu_) is read: ct_ becomes a copy of the CT's geometry
// and dictionary without voxels, and the caller is told it may free the CT's.
void ColonSegmenter::release_ct_voxels() {
  if (!voxels_read_) return;
  // The caller's stand-in is allocated on the heap (the CT in 16 bits, beside the float CT until it
  // is freed): the full-volume gas mask freed into BlockReuse must not add to that moment's peak.
  release_kept_blocks();
  geometry_ = CtImage::New();
  geometry_->CopyInformation(ct_);
  geometry_->SetRegions(ct_->GetLargestPossibleRegion());  // no buffer: a stray voxel read is a null read
  geometry_->SetMetaDataDictionary(ct_->GetMetaDataDictionary());
  ct_ = geometry_.GetPointer();
  voxels_read_();
}

void ColonSegmenter::check_input() {
  const auto size = ct_->GetLargestPossibleRegion().GetSize();
  std::size_t fn[3];
  double fsp[3];
  for (int a = 0; a < 3; ++a) {
    fn[a] = size[a];
    fsp[a] = std::round(ct_->GetSpacing()[a] * 1e4) / 1e4;  // DICOM- and NRRD-derived spacings give the same weights
  }
  full_ = make_dims(fn, fsp);
  for (int a = 0; a < 3; ++a) {
    if (full_.n[a] < 8)
      throw PreconditionError("volume is too small for colon segmentation (" + std::to_string(full_.n[0]) + " x " +
                              std::to_string(full_.n[1]) + " x " + std::to_string(full_.n[2]) + " voxels; need at least 8 per axis)");
    if (!(full_.sp[a] >= 0.1 && full_.sp[a] <= 10))
      throw PreconditionError("absurd voxel spacing " + format_number(ct_->GetSpacing()[0]) + " x " +
                              format_number(ct_->GetSpacing()[1]) + " x " + format_number(ct_->GetSpacing()[2]) +
                              " mm (expected 0.1 to 10 mm per axis)");
  }
  voxel_ml_ = full_.sp[0] * full_.sp[1] * full_.sp[2] / 1000.0;
  const HuTally t = tally_hu(ct_->GetBufferPointer(), full_.total);
  if (t.air < full_.total / 1000 + 1 || t.soft < full_.total / 50)
    throw PreconditionError("not a CT volume in HU: no air (< -800 HU) and soft-tissue (-200..200 HU) ranges (values " +
                            format_number(t.lo) + " .. " + format_number(t.hi) + ")");
}

HuTally tally_hu(const float* hu, std::size_t n) {
  HuTally all;
  std::mutex mu;
  parallel_for(n, [&](std::size_t q0, std::size_t q1) {
    HuTally t;
    for (std::size_t q = q0; q < q1; ++q) {
      const float v = hu[q];
      t.air += v < -800;
      t.soft += v > -200 && v < 200;
      t.lo = std::min(t.lo, v);
      t.hi = std::max(t.hi, v);
    }
    std::lock_guard<std::mutex> lock(mu);  // sums and extremes: the same in any order
    all.air += t.air, all.soft += t.soft;
    all.lo = std::min(all.lo, t.lo), all.hi = std::max(all.hi, t.hi);
  });
  return all;
}

// Gravity as an LPS vector from the option or the DICOM PatientPosition, then as an image axis.
void ColonSegmenter::gravity_from_metadata() {
  const auto D = ct_->GetDirection();
  auto axis_for = [&](int lps, int& axis, int& sign) {
    axis = 0;
    for (int a = 1; a < 3; ++a)
      if (std::abs(D[lps][a]) > std::abs(D[lps][axis])) axis = a;
    sign = D[lps][axis] > 0 ? 1 : -1;
  };
  int sup_sign = 1;
  axis_for(2, sup_axis_, sup_sign);
  sup_pos_ = sup_sign > 0;
  std::string pos = opts_.position;
  gravity_source_ = "option --position " + pos;
  if (pos == "auto") {
    const std::string header = patient_position(ct_);
    static const std::map<std::string, std::string> by_code = {
        {"HFS", "supine"}, {"FFS", "supine"}, {"HFP", "prone"}, {"FFP", "prone"},
        {"HFDR", "right-down"}, {"FFDR", "right-down"}, {"HFDL", "left-down"}, {"FFDL", "left-down"}};
    auto it = by_code.find(header);
    pos = it == by_code.end() ? "levels" : it->second;
    gravity_source_ = it == by_code.end() ? "" : "PatientPosition " + header;
  }
  if (pos == "levels") return;  // decided by gravity_from_levels()
  const int lps = pos == "supine" || pos == "prone" ? 1 : 0;  // LPS axis of gravity
  const int lps_sign = pos == "supine" || pos == "left-down" ? 1 : -1;  // supine: +y; right side down: -x
  int sign = 1;
  axis_for(lps, grav_axis_, sign);
  grav_sign_ = sign * lps_sign;
  gravity_known_ = true;
}

std::array<double, 3> ColonSegmenter::lps_of(const double crop_voxel[3]) const {
  itk::ContinuousIndex<double, 3> ci;
  for (int a = 0; a < 3; ++a) ci[a] = crop_voxel[a] + double(blo_[a]);
  CtImage::PointType p;
  ct_->TransformContinuousIndexToPhysicalPoint(ci, p);
  return {p[0], p[1], p[2]};
}

void ColonSegmenter::decide(const std::string& what, double ml, const double centroid_crop[3], bool kept,
                            const std::string& reason) {
  decisions_.push_back({what, ml, lps_of(centroid_crop), kept, reason});
}

// Report: bodies of at least 1 mL one by one (largest first, at most 200), and every decision
// grouped by (what, kept, reason) with count and volume.
void ColonSegmenter::summarize_decisions() {
  std::stable_sort(decisions_.begin(), decisions_.end(), [](const Decision& a, const Decision& b) { return a.volume_ml > b.volume_ml; });
  std::map<std::tuple<std::string, bool, std::string>, std::pair<std::size_t, double>> groups;
  for (const Decision& dc : decisions_) {
    auto& g = groups[{dc.what, dc.kept, dc.reason}];
    ++g.first;
    g.second += dc.volume_ml;
    if (dc.volume_ml >= 1.0 && st_.decisions.size() < 200)
      st_.decisions.push_back({{"what", dc.what}, {"volume_ml", dc.volume_ml}, {"position_lps_mm", dc.position_lps_mm},
                               {"decision", dc.kept ? "kept" : "rejected"}, {"reason", dc.reason}});
  }
  for (const auto& [key, v] : groups)
    st_.decision_counts.push_back({{"what", std::get<0>(key)}, {"decision", std::get<1>(key) ? "kept" : "rejected"},
                                   {"reason", std::get<2>(key)}, {"count", v.first}, {"volume_ml", v.second}});
}

}  // namespace segment_detail
}  // namespace cf
