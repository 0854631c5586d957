#pragma once
// `colonflat run` holds an artifact that no later stage reads in its type's smaller stand-in
// (ArtifactType::compact, e.g. the CT in 16 bits once reconstruct has read it), so the stages after
// it run with less memory. It stays so through the finishers: a finisher that reads it expands it
// (ArtifactType::expand) when it needs it, the review report after freeing the meshes, so that the
// full-size value never meets the meshes in memory.
#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "colonflat/core/stage.h"
#include "run_plan.h"

namespace cf {

class ParkedArtifacts {
 public:
  // After plan.stages[done] ran and its outputs went to the background writer: every artifact in
  // `bag` with a compactable type that none of the stages after it reads, and that neither that
  // stage nor a later one writes (the writer may still be writing stage `done`'s outputs; it has
  // written every earlier stage's, BackgroundOutputWriter::submit waits for them), is replaced by
  // its stand-in; each one parked is appended to `log` ({"artifact", "after_stage", "time_s"}).
  // E.g. segment's lumen mask is parked after reconstruct, when segment's files are written.
  void park_unread(const RunPlan& plan, std::size_t done, ArtifactBag& bag, nlohmann::json& log);

 private:
  std::map<std::string, const ArtifactType*> parked_;  // name -> its type
};

}  // namespace cf
