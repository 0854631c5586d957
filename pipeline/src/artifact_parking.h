#pragma once
// `colonflat run` holds an artifact that no later stage needs whole in its type's smaller stand-in
// (ArtifactType::compact), so the stages after it run with less memory: e.g. the CT in 16 bits once
// reconstruct has read it, and the surfaces before and after denoising as triangle lists from denoise
// on (flatten and render declare those inputs Port::reads_stand_in). It stays so through the
// finishers: a finisher that reads it expands it (ArtifactType::expand) when it needs it, the review
// report after freeing the meshes, so that the full-size value never meets the meshes in memory.
#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "colonflat/core/stage.h"
#include "run_plan.h"

namespace cf {

class ParkedArtifacts {
 public:
  // After plan.stages[done] ran, before its outputs go to the background writer: each of its own
  // outputs with a compactable type that no later stage writes, that a later stage reads, and that
  // every later stage reading it takes as a stand-in is replaced by its stand-in (the writer then
  // writes the stand-in, which gives the same file: ArtifactType::write). E.g. denoise's
  // "denoised", read by flatten and render. An output no later stage reads is left whole for its
  // writer (nothing would run smaller meanwhile); park_unread takes it after the next stage.
  void park_outputs(const RunPlan& plan, std::size_t done, ArtifactBag& bag, nlohmann::json& log);
  // After plan.stages[done]'s outputs went to the writer: every other artifact in `bag` with a
  // compactable type that every stage after it reading it takes as a stand-in (none reading it
  // included), and that neither that stage nor a later one writes (the writer may still be writing
  // stage `done`'s outputs; it has written every earlier stage's, BackgroundOutputWriter::submit
  // waits for them), is replaced by its stand-in. E.g. segment's lumen mask after reconstruct, and
  // reconstruct's surface after denoise. Each one parked is appended to `log` ({"artifact",
  // "after_stage", "time_s"}), by both calls.
  void park_unread(const RunPlan& plan, std::size_t done, ArtifactBag& bag, nlohmann::json& log);
  // While plan.stages[running] runs, when it has released its input `port`
  // (RunContext::release_input): that input is replaced by its stand-in when its type is
  // compactable, neither the previous stage (its writer may still be at work), this one nor a later
  // one writes it, and every later stage reading it takes the stand-in (none reading it included:
  // the rest of this stage runs smaller). E.g. the CT after segment's crop. Logged as
  // {"artifact", "during_stage", "time_s"}.
  void park_released(const RunPlan& plan, std::size_t running, const std::string& port, ArtifactBag& bag,
                     nlohmann::json& log);

 private:
  void park(const std::string& name, const ArtifactType& type, const std::string& stage, ArtifactBag& bag,
            nlohmann::json& log, const char* when = "after_stage");
  std::map<std::string, const ArtifactType*> parked_;  // name -> its type
};

}  // namespace cf
