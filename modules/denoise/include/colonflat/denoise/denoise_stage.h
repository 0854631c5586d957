#pragma once
// `colonflat denoise IN -o OUT [--loops F] [--report F] [--method exact|paper] [--policy P]
//  [--max-loop-length L] [--target-genus G]` and its pipeline stage.
#include <memory>

#include "colonflat/core/stage.h"
#include "colonflat/denoise/denoise.h"

namespace cf {

class DenoiseStage : public StageWithOptions<DenoiseOptions> {
 public:
  const StageSpec& spec() const override;
  void run(ArtifactBag& bag, RunContext& ctx) override;

 protected:
  const ParamTable<DenoiseOptions>& table() const override;
};

std::unique_ptr<Stage> make_denoise_stage();

}  // namespace cf
