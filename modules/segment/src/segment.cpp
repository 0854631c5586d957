#include "colonflat/segment/segment.h"

#include "colonflat/core/error.h"

namespace cf {

nlohmann::json SegmentStats::to_json() const {
  return {{"segments", segments},
          {"segment_volumes_ml", segment_volumes_ml},
          {"lumen_volume_ml", lumen_volume_ml},
          {"fluid_volume_ml", fluid_volume_ml},
          {"class_means_hu", {{"air", air_hu}, {"tissue", tissue_hu}, {"fluid", fluid_hu}}},
          {"band_voxels", band_voxels},
          {"graph_edges", graph_edges},
          {"max_flow", flow},
          {"removed_components", removed_components},
          {"time_s", time_s},
          {"graph_cut_time_s", graph_cut_time_s},
          {"peak_memory_mib", peak_memory_mib}};
}

void validate(const SegmentOptions& o) { (void)o; }

MaskImage::Pointer segment_colon(const CtImage* ct, const SegmentOptions& opts, SegmentStats* stats) {
  throw Error("segment_colon: not implemented yet");
}

}  // namespace cf
