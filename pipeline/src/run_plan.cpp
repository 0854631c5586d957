// `colonflat run`: every check before the first stage starts (issue 16: fail in < 1 s).
#include <algorithm>

#include "colonflat/core/error.h"
#include "colonflat/core/output_check.h"
#include "colonflat/core/stage_runner.h"
#include "colonflat/pipeline/registry.h"
#include "run_plan.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

// "stage.param=value" -> (stage, param, JSON value); value parsed as JSON when it is valid JSON.
void apply_set(const std::string& s, RunPlan& plan) {
  const auto dot = s.find('.');
  const auto eq = s.find('=');
  if (dot == std::string::npos || eq == std::string::npos || dot > eq)
    throw UsageError("--set expects STAGE.PARAM=VALUE (got '" + s + "')");
  const std::string stage = s.substr(0, dot), param = s.substr(dot + 1, eq - dot - 1), value = s.substr(eq + 1);
  for (auto& st : plan.stages)
    if (st->spec().name == stage) {
      nlohmann::json v = nlohmann::json::parse(value, nullptr, false);
      if (v.is_discarded()) v = value;
      st->set_params_json({{param, v}}, "--set " + s);
      return;
    }
  throw UsageError("--set " + s + ": no stage '" + stage + "' in this run");
}

void apply_params_file(const std::string& file, RunPlan& plan) {
  nlohmann::json j = read_json_file(file);
  if (!j.is_object()) throw InputError(file, "parameters must be a JSON object keyed by stage name");
  for (auto it = j.begin(); it != j.end(); ++it) {
    Stage* target = nullptr;
    for (auto& st : plan.stages)
      if (st->spec().name == it.key()) target = st.get();
    if (target) target->set_params_json(it.value(), file);
    else if (!find_stage(it.key())) throw InputError(file, "unknown stage '" + it.key() + "'");
  }
}

void choose_stages(const RunOptions& o, RunPlan& plan) {
  const std::vector<std::string> names = available_stages();
  if (names.empty()) throw Error("this build has no pipeline stages");
  auto index_of = [&](const std::string& s) -> std::size_t {
    for (std::size_t i = 0; i < names.size(); ++i)
      if (names[i] == s) return i;
    throw UsageError("unknown or unavailable stage '" + s + "' (available: " + joined(names) + ")");
  };
  const std::size_t first = o.from.empty() ? 0 : index_of(o.from);
  const std::size_t last = o.to.empty() ? names.size() - 1 : index_of(o.to);
  if (first > last) throw UsageError("--from " + o.from + " comes after --to " + o.to);
  plan.first_index = first;
  for (std::size_t i = first; i <= last; ++i) plan.stages.push_back(find_stage(names[i])());
  for (const auto& s : pipeline_stage_order())
    if (std::find(names.begin() + first, names.begin() + last + 1, s) == names.begin() + last + 1)
      plan.not_run.push_back(s);
}

// Every required input port of every stage is produced by an earlier stage (or is the run's
// input), with the same artifact type.
void check_port_chain(const RunPlan& plan) {
  std::map<std::string, const ArtifactType*> produced;
  const Port& head = plan.stages.front()->spec().inputs.at(0);
  produced[head.name] = head.type;
  for (const auto& st : plan.stages) {
    const StageSpec& spec = st->spec();
    for (const Port& p : spec.inputs) {
      auto it = produced.find(p.name);
      if (it == produced.end()) {
        if (p.required)
          throw UsageError("stage " + spec.name + " needs '" + p.name + "' (" + p.file_name +
                           "), which no earlier stage of this run produces; start earlier with --from");
        continue;
      }
      if (it->second->name != p.type->name)
        throw UsageError("stage " + spec.name + " reads '" + p.name + "' as " + p.type->name + ", but it is a " +
                         it->second->name);
    }
    for (const Port& p : spec.outputs) produced[p.name] = p.type;
  }
}

// Registered tools that are also RunFinishers and apply to the stages of this run.
void choose_finishers(RunPlan& plan) {
  std::vector<std::string> names;
  for (const auto& st : plan.stages) names.push_back(st->spec().name);
  for (auto& tool : registered_module_tools()) {
    auto* finisher = dynamic_cast<RunFinisher*>(tool.get());
    if (finisher && finisher->applies_to(names)) plan.finishers.push_back(std::move(tool));
  }
}

void check_input(RunOptions& o, const RunPlan& plan) {
  const Port& head = plan.stages.front()->spec().inputs.at(0);
  if (o.input.empty()) {
    if (plan.first_index != 0 || plan.stages.front()->spec().name != "segment")
      throw UsageError("INPUT is required when the run does not start with segmentation");
    return;
  }
  check_input_file(o.input, head.type->name == "volume");
}

// Outputs: OUTDIR/<port files>, the run reports, --params-out and the debug folder; none may be
// an input, none written twice, and OUTDIR may not be the folder holding the input or a phantom.
void check_outputs(const RunOptions& o, const RunPlan& plan) {
  const fs::path out(o.outdir);
  std::error_code ec;
  if (fs::exists(out / "phantom.json", ec))
    throw UsageError(o.outdir + ": -o is a phantom folder (phantom.json): its ground truth would be replaced; "
                     "use a fresh folder, e.g. -o " + (out / "run").string());
  PathPlan paths;
  paths.input(o.input);
  if (!o.params_in.empty()) paths.input(o.params_in);
  if (!o.input.empty() && fs::is_regular_file(o.input, ec) && same_file(fs::absolute(o.input).parent_path(), out))
    throw UsageError(o.outdir + ": -o is the folder holding the input " + o.input +
                     "; use a fresh folder, e.g. -o " + (out / "run").string());
  paths.output_folder(out, "-o");
  if (!o.debug_dir.empty()) paths.output_folder(o.debug_dir, "--debug-dir");
  for (const auto& st : plan.stages)
    for (const Port& p : st->spec().outputs) plan_port_output(paths, p, out / p.file_name, "-o (" + p.name + ")");
  for (const auto& tool : plan.finishers) {
    for (const auto& file : as_finisher(*tool).planned_outputs(out)) paths.output(file, "-o (" + tool->name() + ")");
    for (const auto& dir : as_finisher(*tool).planned_folders(out)) paths.output_folder(dir, "-o (" + tool->name() + ")");
  }
  paths.output(out / "run_report.json", "-o (run report)");
  paths.output(out / "run_report.txt", "-o (run report)");
  if (!o.params_out.empty()) paths.output(o.params_out, "--params-out", {".json"});
  paths.check();
}

}  // namespace

RunFinisher& as_finisher(Tool& tool) {
  auto* finisher = dynamic_cast<RunFinisher*>(&tool);
  if (!finisher) throw Error(tool.name() + " does not finish runs");
  return *finisher;
}

std::vector<std::string> available_stages() {
  std::vector<std::string> v;
  for (const auto& n : pipeline_stage_order())
    if (find_stage(n)) v.push_back(n);
  return v;
}

RunPlan plan_run(RunOptions& o) {
  RunPlan plan;
  choose_stages(o, plan);
  if (!o.params_in.empty()) apply_params_file(o.params_in, plan);
  for (const auto& s : o.sets) apply_set(s, plan);
  for (const auto& st : plan.stages) st->validate_params();
  check_port_chain(plan);
  choose_finishers(plan);
  check_input(o, plan);
  check_outputs(o, plan);
  plan.generate_input = o.input.empty();
  return plan;
}

}  // namespace cf
