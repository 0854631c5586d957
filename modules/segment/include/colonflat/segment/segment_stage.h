#pragma once
// The "segment" pipeline stage: ct (volume) -> mask (lumen_mask.nrrd).
#include <memory>

#include "colonflat/core/stage.h"
#include "colonflat/segment/segment.h"

namespace cf {

class SegmentStage : public StageWithOptions<SegmentOptions> {
 public:
  const StageSpec& spec() const override;
  void run(ArtifactBag& bag, RunContext& ctx) override;

 protected:
  const ParamTable<SegmentOptions>& table() const override;
};

std::unique_ptr<Stage> make_segment_stage();

}  // namespace cf
