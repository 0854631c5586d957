#pragma once
// `colonflat flatten DENOISED -o FLAT.vtp [parameters: flatten_params.def]`: the pipeline stage
// around cf::flatten_colon().
#include <memory>

#include "colonflat/core/stage.h"
#include "colonflat/flatten/flat_artifact.h"
#include "colonflat/flatten/flatten.h"

namespace cf {

class FlattenStage : public StageWithOptions<FlattenOptions> {
 public:
  const StageSpec& spec() const override;
  void run(ArtifactBag& bag, RunContext& ctx) override;

 protected:
  const ParamTable<FlattenOptions>& table() const override { return flatten_param_table(); }
};

std::unique_ptr<Stage> make_flatten_stage();

}  // namespace cf
