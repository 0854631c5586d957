#pragma once
// The `reconstruct` pipeline stage: "mask" (lumen_mask.nrrd) -> "surface" (surface.vtp).
// Optional input "ct" (the CT the mask was segmented from; `colonflat run` passes it on when it
// starts at segment): the surface then follows the CT's air/tissue boundary.
// `colonflat reconstruct MASK -o SURFACE [--ct CT] [parameters: reconstruct_params.def]
//  [--report stats.json]`.
#include <memory>

#include "colonflat/core/stage.h"
#include "colonflat/reconstruct/reconstruct.h"

namespace cf {

class ReconstructStage : public StageWithOptions<ReconstructOptions> {
 public:
  const StageSpec& spec() const override;
  // The table's ranges and choices, then the rules between parameters.
  void validate_params() const override { validate(opts_); }
  void run(ArtifactBag& bag, RunContext& ctx) override;

 protected:
  const ParamTable<ReconstructOptions>& table() const override { return reconstruct_param_table(); }
};

std::unique_ptr<Stage> make_reconstruct_stage();

}  // namespace cf
