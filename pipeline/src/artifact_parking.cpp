// ParkedArtifacts (artifact_parking.h).
#include "artifact_parking.h"

#include <set>

#include "colonflat/core/run_stats.h"

namespace cf {
namespace {

// The declared type of each artifact name the plan's stages read, and the names that stage
// `done` and the stages after it write.
struct PlanPorts {
  std::map<std::string, const ArtifactType*> type;
  std::set<std::string> written;
};

PlanPorts plan_ports(const RunPlan& plan, std::size_t done) {
  PlanPorts p;
  for (std::size_t j = 0; j < plan.stages.size(); ++j) {
    for (const Port& in : plan.stages[j]->spec().inputs) p.type.emplace(in.name, in.type);
    if (j >= done)
      for (const Port& out : plan.stages[j]->spec().outputs) p.written.insert(out.name);
  }
  return p;
}

bool read_after(const RunPlan& plan, std::size_t done, const std::string& name) {
  for (std::size_t j = done + 1; j < plan.stages.size(); ++j)
    for (const Port& in : plan.stages[j]->spec().inputs)
      if (in.name == name) return true;
  return false;
}

}  // namespace

void ParkedArtifacts::park_unread(const RunPlan& plan, std::size_t done, ArtifactBag& bag, nlohmann::json& log) {
  const PlanPorts ports = plan_ports(plan, done);
  for (const auto& [name, type] : ports.type) {
    if (!type->compact || !type->expand || parked_.count(name) || !bag.has(name)) continue;
    if (ports.written.count(name) || read_after(plan, done, name)) continue;
    Stopwatch sw;
    std::optional<std::any> stand_in = type->compact(bag.raw(name));
    if (!stand_in) continue;
    bag.put(name, std::move(*stand_in));
    parked_[name] = type;
    log.push_back({{"artifact", name}, {"after_stage", plan.stages[done]->spec().name}, {"time_s", sw.seconds()}});
  }
}

}  // namespace cf
