#include "colonflat/segment/segment_stage.h"

#include <sstream>

#include "colonflat/core/run_stats.h"

namespace cf {

const StageSpec& SegmentStage::spec() const {
  static const StageSpec s{
      "segment",
      "colon lumen (air + tagged fluid) from a CT colonography volume, refined by graph cut",
      {{"ct", &volume_artifact(), "CT volume in HU", "ct.nrrd"}},
      {{"mask", &mask_artifact(), "lumen mask (1 = lumen)", "lumen_mask.nrrd"}}};
  return s;
}

const ParamTable<SegmentOptions>& SegmentStage::table() const {
  static const ParamTable<SegmentOptions> t = [] {
    using O = SegmentOptions;
    ParamTable<O> t;
    t.real("air-threshold", &O::air_threshold, "HU", "gas below this value seeds the lumen", -1000, -200);
    t.real("fluid-threshold", &O::fluid_threshold, "HU", "tagged fluid candidate above this value", 50, 1000);
    t.real("fluid-max", &O::fluid_max, "HU", "not fluid above this value (bone, metal)", 300, 4000);
    t.real("interface-width", &O::interface_width, "mm", "air/fluid partial-volume layer taken as lumen", 0, 20);
    t.real("level-tolerance", &O::level_tolerance, "mm",
           "a fluid pool's surface must be level: spread of its height (10th-90th percentile)", 0.5, 50);
    t.real("band-width", &O::band_width, "mm", "half-width of the graph-cut band around the initial boundary", 0.5, 10);
    t.real("smoothness", &O::smoothness, "", "boundary term weight against the data term", 0, 10);
    t.real("edge-sigma", &O::edge_sigma, "HU", "contrast sensitivity of the boundary term", 1, 2000);
    t.real("min-segment-volume", &O::min_segment_volume, "mL", "smaller gas/fluid bodies are not colon", 0, 5000);
    t.real("min-segment-fraction", &O::min_segment_fraction, "",
           "a further segment must reach this fraction of the largest", 0, 1);
    t.real("min-colon-volume", &O::min_colon_volume, "mL",
           "less gas and fluid than this in all segments: no insufflated colon", 0, 10000);
    t.integer("max-segments", &O::max_segments, "", "at most this many colon segments kept", 1, 100);
    t.flag("graph-cut", &O::graph_cut, "refine the boundary by graph cut (off: thresholds only)");
    t.choice("position", &O::position, {"auto", "levels", "supine", "prone", "left-down", "right-down"},
             "gravity: auto = DICOM PatientPosition, else the fluid levels; levels = fluid levels only; or fixed");
    t.real("min-tagged-volume", &O::min_tagged_volume, "mL", "smallest fully tagged colon stretch (no gas) kept", 0.5, 1000);
    t.real("link-gap", &O::link_gap, "mm",
           "widest gap between a fully tagged stretch and the end of the colon segment it continues", 0, 100);
    t.real("tube-area", &O::tube_area, "mm^2",
           "gas channels thinner than this reaching the inferior face (rectal tube) are trimmed; 0 = off", 0, 2000);
    return t;
  }();
  return t;
}

void SegmentStage::run(ArtifactBag& bag, RunContext& ctx) {
  const auto& ct = bag.get<CtImage::Pointer>("ct");
  SegmentStats stats;
  MaskImage::Pointer mask = segment_colon(ct.GetPointer(), opts_, &stats);
  std::ostringstream s;
  s << "segment: " << stats.segments << " segment(s) (" << stats.tagged_stretches << " fully tagged stretch(es)), lumen "
    << format_number(stats.lumen_volume_ml) << " mL, gravity " << stats.gravity << " from " << stats.gravity_source << ", in "
    << format_number(stats.time_s) << " s";
  ctx.progress(s.str());
  ctx.report = stats.to_json();
  bag.put("mask", mask);
}

std::unique_ptr<Stage> make_segment_stage() { return std::make_unique<SegmentStage>(); }

}  // namespace cf
