#pragma once
// The `reconstruct` pipeline stage: "mask" (lumen_mask.nrrd) -> "surface" (surface.vtp).
// `colonflat reconstruct MASK -o SURFACE [--method ...] [--min-component-volume MM3]
//  [--smoothing-iterations N] [--pass-band F] [--target-faces N] [--report stats.json]`.
#include <memory>

#include "colonflat/core/stage.h"
#include "colonflat/reconstruct/reconstruct.h"

namespace cf {

class ReconstructStage : public StageWithOptions<ReconstructOptions> {
 public:
  const StageSpec& spec() const override;
  void run(ArtifactBag& bag, RunContext& ctx) override;

 protected:
  const ParamTable<ReconstructOptions>& table() const override { return reconstruct_param_table(); }
};

std::unique_ptr<Stage> make_reconstruct_stage();

}  // namespace cf
