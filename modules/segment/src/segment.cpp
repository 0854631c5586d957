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
#include <numeric>
#include <sstream>

#include <sys/resource.h>

#include "colonflat/core/error.h"
#include "colonflat/core/progress.h"
#include "colonflat/core/params.h"
#include "segment_internal.h"

namespace cf {

nlohmann::json SegmentStats::to_json() const {
  return {{"segments", segments},
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
}

void validate(const SegmentOptions& o) {
  auto check = [](bool ok, const std::string& what) {
    if (!ok) throw UsageError(what);
  };
  auto num = [](double v) { return " (got " + format_number(v) + ")"; };
  check(o.air_threshold >= -1000 && o.air_threshold <= -200, "--air-threshold must be in [-1000, -200] HU" + num(o.air_threshold));
  check(o.fluid_threshold >= 50 && o.fluid_threshold <= 1000, "--fluid-threshold must be in [50, 1000] HU" + num(o.fluid_threshold));
  check(o.fluid_max > o.fluid_threshold && o.fluid_max <= 4000, "--fluid-max must be above --fluid-threshold and <= 4000 HU" + num(o.fluid_max));
  check(o.interface_width >= 0 && o.interface_width <= 20, "--interface-width must be in [0, 20] mm" + num(o.interface_width));
  check(o.level_tolerance >= 0.5 && o.level_tolerance <= 50, "--level-tolerance must be in [0.5, 50] mm" + num(o.level_tolerance));
  check(o.band_width >= 0.5 && o.band_width <= 10, "--band-width must be in [0.5, 10] mm" + num(o.band_width));
  check(o.smoothness >= 0 && o.smoothness <= 10, "--smoothness must be in [0, 10]" + num(o.smoothness));
  check(o.edge_sigma >= 1 && o.edge_sigma <= 2000, "--edge-sigma must be in [1, 2000] HU" + num(o.edge_sigma));
  check(o.min_segment_volume >= 0 && o.min_segment_volume <= 5000, "--min-segment-volume must be in [0, 5000] mL" + num(o.min_segment_volume));
  check(o.min_colon_volume >= 0 && o.min_colon_volume <= 10000, "--min-colon-volume must be in [0, 10000] mL" + num(o.min_colon_volume));
  check(o.min_segment_fraction >= 0 && o.min_segment_fraction <= 1, "--min-segment-fraction must be in [0, 1]" + num(o.min_segment_fraction));
  check(o.max_segments >= 1 && o.max_segments <= 100, "--max-segments must be in [1, 100] (got " + std::to_string(o.max_segments) + ")");
  check(o.min_tagged_volume >= 0.5 && o.min_tagged_volume <= 1000, "--min-tagged-volume must be in [0.5, 1000] mL" + num(o.min_tagged_volume));
  check(o.link_gap >= 0 && o.link_gap <= 100, "--link-gap must be in [0, 100] mm" + num(o.link_gap));
  check(o.tube_area >= 0 && o.tube_area <= 2000, "--tube-area must be in [0, 2000] mm^2" + num(o.tube_area));
  static const std::vector<std::string> positions = {"auto", "levels", "supine", "prone", "left-down", "right-down"};
  check(std::find(positions.begin(), positions.end(), o.position) != positions.end(),
        "--position must be one of auto, levels, supine, prone, left-down, right-down (got '" + o.position + "')");
}

MaskImage::Pointer segment_colon(const CtImage* ct, const SegmentOptions& opts, SegmentStats* stats_out) {
  validate(opts);
  if (!ct) throw PreconditionError("segment: no volume");
  return segment_detail::ColonSegmenter(ct, opts).run(stats_out);
}

namespace segment_detail {

double process_cpu_seconds() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return double(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) + 1e-6 * double(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

MaskImage::Pointer ColonSegmenter::run(SegmentStats* stats) {
  cpu_start_ = cpu_lap_ = process_cpu_seconds();
  check_input();
  gravity_from_metadata();
  lap("checks");
  find_gas_bodies();
  find_fluid_bodies();
  if (!gravity_known_) gravity_from_levels();
  keep_level_pools();
  mark_layer();
  lap("tagged_fluid");
  select_segments();
  link_tagged_stretches();
  lap("segments");
  class_means();
  lap("class_means");
  refine_boundary();
  lap("graph_cut");
  final_segments();
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
  const float* fhu = ct_->GetBufferPointer();
  std::size_t air = 0, soft = 0;
  float lo = std::numeric_limits<float>::infinity(), hi = -lo;
  for (std::size_t q = 0; q < full_.total; ++q) {
    const float v = fhu[q];
    air += v < -800;
    soft += v > -200 && v < 200;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  if (air < full_.total / 1000 + 1 || soft < full_.total / 50)
    throw PreconditionError("not a CT volume in HU: no air (< -800 HU) and soft-tissue (-200..200 HU) ranges (values " +
                            format_number(lo) + " .. " + format_number(hi) + ")");
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
