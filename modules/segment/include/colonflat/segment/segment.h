#pragma once
// Colon lumen segmentation of a CT colonography volume (docs/segment.md): lumen = air and tagged
// fluid inside the body; outside air, lungs and other gas removed; the colon kept as one or a few
// segments; boundary refined by a graph cut (Boykov-Kolmogorov max-flow) on a narrow band with
// partial-volume data terms and contrast-sensitive smoothness; the air/fluid partial-volume layer
// is kept inside the lumen.
//
//   cf::SegmentStats stats;
//   cf::MaskImage::Pointer mask = cf::segment_colon(ct, cf::SegmentOptions{}, &stats);
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colonflat/volume/volume_io.h"

namespace cf {

struct SegmentOptions {
  double air_threshold = -600;        // HU; below: gas (seed of the lumen)
  double fluid_threshold = 200;       // HU; above (and below fluid-max): tagged-fluid candidate
  double fluid_max = 1400;            // HU; above: not fluid (metal, dense bone)
  double interface_width = 3.0;       // mm; air/fluid layer thickness taken as lumen
  double level_tolerance = 4.0;       // mm; spread (10th-90th percentile) of a fluid pool's surface height
  double band_width = 2.0;            // mm; half-width of the graph-cut band around the initial boundary
  double smoothness = 0.5;            // weight of the boundary (smoothness) term against the data term
  double edge_sigma = 60;             // HU; contrast sensitivity of the smoothness term
  double min_segment_volume = 20;     // mL; smaller gas/fluid bodies are not colon
  double min_segment_fraction = 0.05; // fraction of the largest kept segment a further segment must reach
  double min_colon_volume = 100;      // mL; less gas + fluid in all kept segments: no (insufflated) colon
  int max_segments = 6;               // at most this many colon segments kept
  bool graph_cut = true;              // refine the boundary by graph cut (off: thresholds only)
  // Gravity: "auto" = from the DICOM PatientPosition (0018,5100) and the image direction, else from
  // the fluid levels; "levels" = from the fluid levels only; or fixed: supine, prone, left-down, right-down.
  std::string position = "auto";
  double min_tagged_volume = 5;       // mL; smallest fully tagged colon stretch considered
  double link_gap = 25;               // mm; widest gap between a fully tagged stretch and the gas segment it continues
  double tube_area = 150;             // mm^2; thinner gas channels reaching the inferior face (rectal tube) are trimmed (0: off)
};

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
  double time_s = 0, graph_cut_time_s = 0;
  double peak_memory_mib = 0;
  nlohmann::json timings;  // seconds per step (wall clock)
  double cpu_time_s = 0;        // user + system CPU time of the process during segment_colon (all threads)
  nlohmann::json cpu_timings;   // user + system CPU seconds per step
  nlohmann::json to_json() const;
};

// Segments the colon lumen (1 = lumen). Throws UsageError for invalid options, PreconditionError
// for a volume that is not CT-like, has absurd spacing, or in which no colon is found.
MaskImage::Pointer segment_colon(const CtImage* ct, const SegmentOptions& opts = {}, SegmentStats* stats = nullptr);

// Checks the options (UsageError naming the first bad one).
void validate(const SegmentOptions& opts);

}  // namespace cf
