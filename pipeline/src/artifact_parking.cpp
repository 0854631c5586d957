// ParkedArtifacts (artifact_parking.h).
#include "artifact_parking.h"

#include "colonflat/core/malloc_tunables.h"
#include "colonflat/core/run_stats.h"

namespace cf {
namespace {

// The declared type of each artifact name the plan's stages read.
std::map<std::string, const ArtifactType*> read_types(const RunPlan& plan) {
  std::map<std::string, const ArtifactType*> type;
  for (const auto& st : plan.stages)
    for (const Port& in : st->spec().inputs) type.emplace(in.name, in.type);
  return type;
}

// Whether stage `from` or a later one writes `name`.
bool written_from(const RunPlan& plan, std::size_t from, const std::string& name) {
  for (std::size_t j = from; j < plan.stages.size(); ++j)
    for (const Port& out : plan.stages[j]->spec().outputs)
      if (out.name == name) return true;
  return false;
}

// Whether a stage after `done` reads `name`; `whole`: only as the full value (an input port not
// declared reads_stand_in).
bool read_after(const RunPlan& plan, std::size_t done, const std::string& name, bool whole = false) {
  for (std::size_t j = done + 1; j < plan.stages.size(); ++j)
    for (const Port& in : plan.stages[j]->spec().inputs)
      if (in.name == name && !(whole && in.reads_stand_in)) return true;
  return false;
}

bool read_whole_after(const RunPlan& plan, std::size_t done, const std::string& name) {
  return read_after(plan, done, name, true);
}

bool compactable(const ArtifactType& type) { return type.compact && type.expand; }

}  // namespace

void ParkedArtifacts::park(const std::string& name, const ArtifactType& type, const std::string& stage,
                           ArtifactBag& bag, nlohmann::json& log, const char* when) {
  Stopwatch sw;
  std::optional<std::any> stand_in = type.compact(bag.raw(name));
  if (!stand_in) return;
  bag.put(name, std::move(*stand_in));
  release_free_memory();  // the full value's pages back to the kernel now, not after the next stage
  parked_[name] = &type;
  log.push_back({{"artifact", name}, {when, stage}, {"time_s", sw.seconds()}});
}

void ParkedArtifacts::park_outputs(const RunPlan& plan, std::size_t done, ArtifactBag& bag, nlohmann::json& log) {
  for (const Port& out : plan.stages[done]->spec().outputs) {
    if (!compactable(*out.type) || parked_.count(out.name) || !bag.has(out.name)) continue;
    if (written_from(plan, done + 1, out.name) || read_whole_after(plan, done, out.name)) continue;
    if (!read_after(plan, done, out.name)) continue;  // nothing gained before its file: park_unread, after
    park(out.name, *out.type, plan.stages[done]->spec().name, bag, log);
  }
}

void ParkedArtifacts::park_unread(const RunPlan& plan, std::size_t done, ArtifactBag& bag, nlohmann::json& log) {
  for (const auto& [name, type] : read_types(plan)) {
    if (!compactable(*type) || parked_.count(name) || !bag.has(name)) continue;
    if (written_from(plan, done, name) || read_whole_after(plan, done, name)) continue;
    park(name, *type, plan.stages[done]->spec().name, bag, log);
  }
}

void ParkedArtifacts::park_released(const RunPlan& plan, std::size_t running, const std::string& port,
                                    ArtifactBag& bag, nlohmann::json& log) {
  const Stage& stage = *plan.stages[running];
  for (const Port& in : stage.spec().inputs) {
    if (in.name != port || !compactable(*in.type) || parked_.count(port) || !bag.has(port)) continue;
    // (the writer may still be writing the previous stage's outputs)
    if (written_from(plan, running ? running - 1 : 0, port) || read_whole_after(plan, running, port)) continue;
    park(port, *in.type, stage.spec().name, bag, log, "during_stage");
  }
}

}  // namespace cf
