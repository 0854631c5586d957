#pragma once
// `colonflat denoise IN -o OUT [--loops F] [--report F] [--method exact|paper] [--policy P]
//  [--max-loop-length L] [--target-genus G] [--ring-pull F] [--[no-]check-caps] [--strict]
//  [--remove-stumps MM] [--initial-radius MM]` and its pipeline stage (parameters: table() in
//  denoise_stage.cpp, the one place they are declared; docs/denoise.md).
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
