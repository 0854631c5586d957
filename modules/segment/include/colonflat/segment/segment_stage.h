#pragma once
// The "segment" pipeline stage: ct (volume) -> mask (lumen_mask.nrrd).
// `colonflat segment CT -o MASK [--report F] [parameters: segment_params.def]`.
#include <memory>

#include "colonflat/core/stage.h"
#include "colonflat/segment/segment.h"

namespace cf {

class SegmentStage : public StageWithOptions<SegmentOptions> {
 public:
  const StageSpec& spec() const override;
  // The table's ranges and choices, then the rules between parameters.
  void validate_params() const override { validate(opts_); }
  void run(ArtifactBag& bag, RunContext& ctx) override;

 protected:
  const ParamTable<SegmentOptions>& table() const override { return segment_param_table(); }
};

std::unique_ptr<Stage> make_segment_stage();

}  // namespace cf
