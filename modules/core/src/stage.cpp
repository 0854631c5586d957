#include "colonflat/core/stage.h"

#include <algorithm>
#include <fstream>
#include <iostream>

#include "colonflat/core/atomic_file.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/core/stage_runner.h"

namespace fs = std::filesystem;

namespace cf {

const std::any& ArtifactBag::raw(const std::string& name) const {
  auto it = items_.find(name);
  if (it == items_.end()) throw Error("missing artifact '" + name + "'");
  return it->second;
}

nlohmann::json read_json_file(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string(), fs::exists(path) ? "cannot open for reading" : "no such file");
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError(path.string(), std::string("invalid JSON: ") + e.what());
  }
}

namespace {

// Files named on the command line of a stand-alone stage.
struct StageFiles {
  std::map<std::string, std::string> inputs, outputs;  // port -> file
  std::string report, params_in, params_out;
  bool quiet = false;
};

// Option name of a secondary port: kebab-case ("snapshot_before" -> "--snapshot-before").
std::string port_option(const Port& p) {
  std::string n = p.name;
  std::replace(n.begin(), n.end(), '_', '-');
  return "--" + n;
}

void add_port_options(CLI::App& app, const StageSpec& spec, StageFiles& f) {
  for (std::size_t i = 0; i < spec.inputs.size(); ++i) {
    const Port& p = spec.inputs[i];
    const std::string desc = p.help + ": " + p.type->description;
    if (i == 0) app.add_option("input", f.inputs[p.name], desc)->required()->type_name("FILE");
    else {
      auto* o = app.add_option(port_option(p), f.inputs[p.name], desc)->type_name("FILE");
      if (p.required) o->required();
    }
  }
  for (std::size_t i = 0; i < spec.outputs.size(); ++i) {
    const Port& p = spec.outputs[i];
    const std::string desc = p.help + ": " + p.type->description;
    if (i == 0) app.add_option("-o,--output", f.outputs[p.name], desc)->required()->type_name("FILE");
    else app.add_option(port_option(p), f.outputs[p.name], desc + " (optional)")->type_name("FILE");
  }
  app.add_option("--report", f.report, "write the stage report (parameters, counts, time, memory) as JSON")
      ->type_name("FILE.json");
  app.add_option("--params-in", f.params_in, "read parameters from JSON (command-line values win)")
      ->type_name("FILE.json");
  app.add_option("--params-out", f.params_out, "write the effective parameters as JSON")->type_name("FILE.json");
  app.add_flag("-q,--quiet", f.quiet, "no progress output");
}

// Every output path against the others and against every input, before any work.
void check_stage_paths(const StageSpec& spec, const StageFiles& f) {
  PathPlan plan;
  for (const Port& p : spec.inputs) plan.input(f.inputs.at(p.name));
  if (!f.params_in.empty()) plan.input(f.params_in);
  for (std::size_t i = 0; i < spec.outputs.size(); ++i) {
    const Port& p = spec.outputs[i];
    const std::string& file = f.outputs.at(p.name);
    if (i == 0 || !file.empty()) plan_port_output(plan, p, file, i == 0 ? "-o" : port_option(p));
  }
  if (!f.report.empty()) plan.output(f.report, "--report", {".json"});
  if (!f.params_out.empty()) plan.output(f.params_out, "--params-out", {".json"});
  plan.check();
  for (const Port& p : spec.inputs)
    if (!f.inputs.at(p.name).empty()) check_input_file(f.inputs.at(p.name), p.type->name == "volume");
}

class StageTool : public Tool {
 public:
  explicit StageTool(StageFactory f) : factory_(std::move(f)), probe_(factory_()) {}
  std::string name() const override { return probe_->spec().name; }
  std::string summary() const override { return probe_->spec().summary; }

  int run(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) override {
    auto stage = factory_();
    const StageSpec& spec = stage->spec();
    CLI::App app(spec.summary, "colonflat " + spec.name);
    app.set_version_flag("--version", colonflat_version());
    StageFiles files;
    add_port_options(app, spec, files);
    stage->add_cli_options(app);
    return run_cli(app, spec.name, args, out, err, [&]() -> int {
      if (!files.params_in.empty()) apply_params_file(*stage, app, args, files.params_in);
      stage->validate_params();
      check_stage_paths(spec, files);
      run_and_write(*stage, files, err);
      return kExitOk;
    });
  }

 private:
  // Applies the file first, then re-parses so that command-line values take precedence.
  static void apply_params_file(Stage& stage, CLI::App& app, const std::vector<std::string>& args,
                                const std::string& file) {
    nlohmann::json j = read_json_file(file);
    if (j.is_object() && j.contains(stage.spec().name)) j = j[stage.spec().name];
    stage.set_params_json(j, file);
    std::vector<std::string> reversed(args.rbegin(), args.rend());
    app.clear();
    app.parse(reversed);
  }

  static void run_and_write(Stage& stage, const StageFiles& files, std::ostream& err) {
    const StageSpec& spec = stage.spec();
    Stopwatch total;
    ArtifactBag bag;
    nlohmann::json inputs = nlohmann::json::object();
    for (const Port& p : spec.inputs) {
      const std::string& f = files.inputs.at(p.name);
      if (f.empty()) continue;
      bag.put(p.name, p.type->read(f));
      bag.put(p.name + ".file", f);  // the file name, for error lines that name the input
      inputs[p.name] = f;
    }
    RunContext ctx;
    ctx.log = files.quiet ? nullptr : &err;
    nlohmann::json record = run_stage_recorded(stage, bag, ctx);
    OutputTransaction tx;
    std::map<std::string, fs::path> targets(files.outputs.begin(), files.outputs.end());
    write_stage_outputs(stage, bag, targets, tx, record);
    record["version"] = colonflat_version();
    record["inputs"] = inputs;
    record["total_time_s"] = total.seconds();
    if (!files.report.empty()) std::ofstream(tx.stage(files.report)) << record.dump(2) << "\n";
    if (!files.params_out.empty())
      std::ofstream(tx.stage(files.params_out)) << nlohmann::json{{spec.name, stage.params_json()}}.dump(2) << "\n";
    tx.commit();
  }

  StageFactory factory_;
  std::unique_ptr<Stage> probe_;
};

}  // namespace

std::unique_ptr<Tool> make_stage_tool(StageFactory factory) { return std::make_unique<StageTool>(std::move(factory)); }

}  // namespace cf
