#include "colonflat/core/stage.h"

#include <fstream>
#include <iostream>

#include "colonflat/core/atomic_file.h"
#include "colonflat/core/run_stats.h"

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
    std::map<std::string, std::string> in_files, out_files;
    std::string report_file, params_in, params_out;
    bool quiet = false;
    for (std::size_t i = 0; i < spec.inputs.size(); ++i) {
      const Port& p = spec.inputs[i];
      const std::string desc = p.help + ": " + p.type->description;
      if (i == 0) app.add_option("input", in_files[p.name], desc)->required()->type_name("FILE");
      else {
        auto* o = app.add_option("--" + p.name, in_files[p.name], desc)->type_name("FILE");
        if (p.required) o->required();
      }
    }
    for (std::size_t i = 0; i < spec.outputs.size(); ++i) {
      const Port& p = spec.outputs[i];
      const std::string desc = p.help + ": " + p.type->description;
      if (i == 0) app.add_option("-o,--output", out_files[p.name], desc)->required()->type_name("FILE");
      else app.add_option("--" + p.name, out_files[p.name], desc + " (optional)")->type_name("FILE");
    }
    app.add_option("--report", report_file, "write the stage report (parameters, counts, time, memory) as JSON")
        ->type_name("FILE.json");
    app.add_option("--params-in", params_in, "read parameters from JSON (command-line values win)")
        ->type_name("FILE.json");
    app.add_option("--params-out", params_out, "write the effective parameters as JSON")->type_name("FILE.json");
    app.add_flag("-q,--quiet", quiet, "no progress output");
    stage->add_cli_options(app);
    return run_cli(app, spec.name, args, out, err, [&]() -> int {
      if (!params_in.empty()) {
        // Apply the file first, then re-parse so that command-line values take precedence.
        nlohmann::json j = read_json_file(params_in);
        if (j.contains(spec.name)) j = j[spec.name];
        stage->set_params_json(j, params_in);
        std::vector<std::string> reversed(args.rbegin(), args.rend());
        app.clear();
        app.parse(reversed);
      }
      stage->validate_params();
      for (const Port& p : spec.outputs)
        for (const Port& q : spec.inputs)
          if (!out_files[p.name].empty() && !in_files[q.name].empty() &&
              fs::weakly_canonical(out_files[p.name]) == fs::weakly_canonical(in_files[q.name]))
            throw UsageError(out_files[p.name] + ": output would overwrite the input");
      Stopwatch total;
      ArtifactBag bag;
      for (const Port& p : spec.inputs) {
        const std::string& f = in_files[p.name];
        if (f.empty()) continue;
        bag.put(p.name, p.type->read(f));
      }
      RunContext ctx;
      ctx.log = quiet ? nullptr : &err;
      Stopwatch t;
      stage->run(bag, ctx);
      const double run_time = t.seconds();
      OutputTransaction tx;
      for (const Port& p : spec.outputs) {
        const std::string& f = out_files[p.name];
        if (f.empty()) continue;
        if (!bag.has(p.name)) throw Error("stage produced no '" + p.name + "' output");
        p.type->write(bag.raw(p.name), tx.stage(f), f);
      }
      nlohmann::json report = {{"stage", spec.name},
                               {"version", colonflat_version()},
                               {"parameters", stage->params_json()},
                               {"result", ctx.report},
                               {"run_time_s", run_time},
                               {"total_time_s", total.seconds()},
                               {"peak_memory_mib", peak_memory_mib()}};
      if (!report_file.empty()) {
        std::ofstream(tx.stage(report_file)) << report.dump(2) << "\n";
      }
      if (!params_out.empty()) {
        std::ofstream(tx.stage(params_out)) << nlohmann::json{{spec.name, stage->params_json()}}.dump(2) << "\n";
      }
      tx.commit();
      return kExitOk;
    });
  }

 private:
  StageFactory factory_;
  std::unique_ptr<Stage> probe_;
};

}  // namespace

std::unique_ptr<Tool> make_stage_tool(StageFactory factory) { return std::make_unique<StageTool>(std::move(factory)); }

}  // namespace cf
