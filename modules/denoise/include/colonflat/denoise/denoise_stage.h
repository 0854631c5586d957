#pragma once
// `colonflat denoise IN -o OUT [--loops F] [--report F] [parameters]` and its pipeline stage.
// The parameters are declared once, in denoise_params.def (--help and docs/denoise.md list them).
#include <memory>

#include "colonflat/core/stage.h"
#include "colonflat/denoise/denoise.h"

namespace cf {

class DenoiseStage : public StageWithOptions<DenoiseOptions> {
 public:
  const StageSpec& spec() const override;
  // The table's ranges and choices, then the rules between parameters.
  void validate_params() const override { validate_denoise_options(opts_); }
  void run(ArtifactBag& bag, RunContext& ctx) override;

 protected:
  const ParamTable<DenoiseOptions>& table() const override { return denoise_param_table(); }
};

std::unique_ptr<Stage> make_denoise_stage();

}  // namespace cf
