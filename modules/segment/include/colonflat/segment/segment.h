#pragma once
// Colon lumen segmentation of a CT colonography volume (docs/segment.md): lumen = air and tagged
// fluid inside the body; outside air, lungs and other gas removed; the colon kept as one or a few
// segments; boundary refined by a graph cut (Boykov-Kolmogorov max-flow) on a narrow band with
// partial-volume data terms and contrast-sensitive smoothness; the air/fluid partial-volume layer
// is kept inside the lumen.
//
//   cf::SegmentStats stats;
//   cf::MaskImage::Pointer mask = cf::segment_colon(ct, cf::SegmentOptions{}, &stats);
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colonflat/volume/volume_io.h"

#include "colonflat/core/params.h"
namespace cf {

// The options of segment: every field is a parameter declared once, with its default, unit, range and
// help, in segment_params.def (also the source of `colonflat segment`'s options and docs/segment.md's table).
struct SegmentOptions {
#define COLONFLAT_PARAMS "colonflat/segment/segment_params.def"
#include "colonflat/core/params_as_fields.h"
};

// The table of SegmentOptions (generated from segment_params.def): option names, units, help, ranges.
const ParamTable<SegmentOptions>& segment_param_table();

struct SegmentStats {
  int segments = 0;
  std::vector<double> segment_volumes_ml;  // largest first
  double lumen_volume_ml = 0;
  double air_hu = 0, tissue_hu = 0, fluid_hu = 0;  // class means estimated from the image
  double fluid_volume_ml = 0;
  std::size_t band_voxels = 0, graph_edges = 0;
  double flow = 0;
  std::size_t removed_components = 0;
  std::size_t rejected_fluid_components = 0;  // bright bodies not kept as colon fluid
  std::string gravity;                        // e.g. "+y (posterior)"
  std::string gravity_source;                 // "PatientPosition HFP", "fluid levels", "option", "default (supine)"
  int tagged_stretches = 0;                   // fully tagged colon stretches kept
  double tagged_stretch_volume_ml = 0;
  double rectal_tube_trimmed_ml = 0;          // thin gas channel trimmed at the inferior face
  nlohmann::json decisions = nlohmann::json::array();  // kept/rejected bodies >= 1 mL: what, volume, LPS, reason
  nlohmann::json decision_counts = nlohmann::json::array();  // every decision, grouped by reason: count, mL
  nlohmann::json links = nlohmann::json::array();  // COLONFLAT_SEGMENT_LINKS=1: every contact the linking step judged
  double time_s = 0, graph_cut_time_s = 0;
  double peak_memory_mib = 0;
  nlohmann::json timings;  // seconds per step (wall clock)
  double cpu_time_s = 0;        // user + system CPU time of the process during segment_colon (all threads)
  nlohmann::json cpu_timings;   // user + system CPU seconds per step
  nlohmann::json to_json() const;
};

// Segments the colon lumen (1 = lumen). Throws UsageError for invalid options, PreconditionError
// for a volume that is not CT-like, has absurd spacing, or in which no colon is found.
// `voxels_read` (optional) is called once, on the calling thread, as soon as the segmentation
// reads no more of ct's voxels: after the crop to the gas (the rest works on its own copy of the
// crop). ct's geometry and metadata dictionary are copied before the call, so the caller may free
// or replace ct's voxel buffer from then on (`colonflat run` holds the CT in 16 bits from there).
MaskImage::Pointer segment_colon(const CtImage* ct, const SegmentOptions& opts = {}, SegmentStats* stats = nullptr,
                                 const std::function<void()>& voxels_read = {});

// Checks the options (UsageError naming the first bad one).
void validate(const SegmentOptions& opts);

}  // namespace cf
