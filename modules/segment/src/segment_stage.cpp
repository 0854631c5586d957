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

const ParamTable<SegmentOptions>& segment_param_table() {
  static const ParamTable<SegmentOptions> table = [](ParamTable<SegmentOptions> t) {
#define COLONFLAT_PARAMS "colonflat/segment/segment_params.def"
#include "colonflat/core/params_as_rows.h"
    return t;
  }({});
  return table;
}

void SegmentStage::run(ArtifactBag& bag, RunContext& ctx) {
  const CtImage* ct = bag.get<CtImage::Pointer>("ct").GetPointer();  // the bag's entry may be replaced from the crop on
  SegmentStats stats;
  MaskImage::Pointer mask = segment_colon(ct, opts_, &stats, [&ctx] { ctx.release_input("ct"); });
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
