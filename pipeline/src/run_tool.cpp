// `colonflat run [INPUT] -o OUTDIR`: chains the stages in memory (pipeline_stage_order()).
#include <algorithm>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "colonflat/core/atomic_file.h"
#include "colonflat/core/error.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/pipeline/registry.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

// "stage.param=value" -> (stage, param, JSON value); value parsed as JSON when it is valid JSON.
void apply_set(const std::string& s, std::map<std::string, std::unique_ptr<Stage>>& by_name) {
  const auto dot = s.find('.');
  const auto eq = s.find('=');
  if (dot == std::string::npos || eq == std::string::npos || dot > eq)
    throw UsageError("--set expects STAGE.PARAM=VALUE (got '" + s + "')");
  const std::string stage = s.substr(0, dot), param = s.substr(dot + 1, eq - dot - 1), value = s.substr(eq + 1);
  auto it = by_name.find(stage);
  if (it == by_name.end()) throw UsageError("--set " + s + ": no stage '" + stage + "' in this run");
  nlohmann::json v = nlohmann::json::parse(value, nullptr, false);
  if (v.is_discarded()) v = value;
  it->second->set_params_json({{param, v}}, "--set " + s);
}

class RunTool : public Tool {
 public:
  std::string name() const override { return "run"; }
  std::string summary() const override { return "the whole pipeline in memory: segment -> ... -> render"; }
  int run(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) override {
    std::vector<std::string> available;
    for (const auto& n : pipeline_stage_order())
      if (find_stage(n)) available.push_back(n);
    std::string all;
    for (const auto& n : available) all += (all.empty() ? "" : ", ") + n;
    CLI::App app("Runs the stages of this build in order (" + all +
                     ") in memory. Without INPUT, generates the full-size phantom (seed 1) into OUTDIR/phantom "
                     "and runs on it. Outputs record units (mm) and coordinate system (LPS).",
                 "colonflat run");
    app.set_version_flag("--version", colonflat_version());
    std::string input, outdir = "colonflat_out", debug_dir, from, to, params_in, params_out;
    std::vector<std::string> sets;
    bool quiet = false;
    app.add_option("input", input, "input of the first stage run (a CT volume, or with --from the file that stage reads)")
        ->type_name("FILE");
    app.add_option("-o,--output", outdir, "output folder (default colonflat_out)")->type_name("DIR");
    app.add_option("--debug-dir", debug_dir, "also write every stage's outputs and a per-stage JSON here")->type_name("DIR");
    app.add_option("--from", from, "first stage to run (" + all + ")")->type_name("STAGE");
    app.add_option("--to", to, "last stage to run")->type_name("STAGE");
    app.add_option("--params-in", params_in, "JSON {stage: {param: value}} of parameters")->type_name("FILE.json");
    app.add_option("--params-out", params_out, "write every effective parameter as JSON")->type_name("FILE.json");
    app.add_option("--set", sets, "set one parameter, e.g. --set denoise.max-loop-length=20 (repeatable)")
        ->type_name("STAGE.PARAM=VALUE");
    app.add_flag("-q,--quiet", quiet, "no progress output");
    return run_cli(app, name(), args, out, err, [&]() -> int {
      if (available.empty()) throw Error("this build has no pipeline stages");
      auto index_of = [&](const std::string& s) -> std::size_t {
        for (std::size_t i = 0; i < available.size(); ++i)
          if (available[i] == s) return i;
        throw UsageError("unknown or unavailable stage '" + s + "' (available: " + all + ")");
      };
      const std::size_t first = from.empty() ? 0 : index_of(from);
      const std::size_t last = to.empty() ? available.size() - 1 : index_of(to);
      if (first > last) throw UsageError("--from " + from + " comes after --to " + to);
      std::vector<std::unique_ptr<Stage>> stages;
      std::map<std::string, std::unique_ptr<Stage>> by_name;
      for (std::size_t i = first; i <= last; ++i) by_name[available[i]] = find_stage(available[i])();
      if (!params_in.empty()) {
        nlohmann::json j = read_json_file(params_in);
        if (!j.is_object()) throw InputError(params_in, "parameters must be a JSON object keyed by stage name");
        for (auto it = j.begin(); it != j.end(); ++it) {
          auto s = by_name.find(it.key());
          if (s == by_name.end()) {
            if (find_stage(it.key())) continue;  // a stage outside --from/--to: ignored
            throw InputError(params_in, "unknown stage '" + it.key() + "'");
          }
          s->second->set_params_json(it.value(), params_in);
        }
      }
      for (const auto& s : sets) apply_set(s, by_name);
      for (auto& [n, s] : by_name) s->validate_params();
      std::ostream* log = quiet ? nullptr : &err;

      ArtifactBag bag;
      const Stage& head = *by_name[available[first]];
      const Port& in_port = head.spec().inputs.at(0);
      if (input.empty()) {
        if (first != 0 || available[0] != "segment")
          throw UsageError("INPUT is required when the run does not start with segmentation");
        input = generate_default_input(outdir, out, err, log);
      }
      if (log) *log << "colonflat run: reading " << input << " as " << in_port.type->name << "\n";
      bag.put(in_port.name, in_port.type->read(input));

      nlohmann::json run_report = {{"version", colonflat_version()},
                                   {"input", input},
                                   {"units", "mm"},
                                   {"coordinate_system", "LPS"},
                                   {"stages", nlohmann::json::array()}};
      nlohmann::json all_params = nlohmann::json::object();
      Stopwatch total;
      OutputTransaction tx;
      const std::size_t n = last - first + 1;
      for (std::size_t i = first; i <= last; ++i) {
        Stage& st = *by_name[available[i]];
        const StageSpec& spec = st.spec();
        if (log) *log << "[" << (i - first + 1) << "/" << n << "] " << spec.name << ": " << spec.summary << "\n";
        RunContext ctx;
        ctx.log = log;
        Stopwatch t;
        st.run(bag, ctx);
        const double secs = t.seconds();
        nlohmann::json sr = {{"stage", spec.name},
                             {"parameters", st.params_json()},
                             {"result", ctx.report},
                             {"time_s", secs},
                             {"peak_memory_mib", peak_memory_mib()},
                             {"outputs", nlohmann::json::object()}};
        all_params[spec.name] = st.params_json();
        for (const Port& p : spec.outputs) {
          if (!bag.has(p.name)) continue;
          p.type->write(bag.raw(p.name), tx.stage(fs::path(outdir) / p.file_name), fs::path(outdir) / p.file_name);
          sr["outputs"][p.name] = p.file_name;
          if (!debug_dir.empty()) {
            const fs::path d = fs::path(debug_dir) / (std::to_string(i + 1) + "_" + spec.name);
            write_atomically(d / p.file_name, [&](const fs::path& tmp) { p.type->write(bag.raw(p.name), tmp, d / p.file_name); });
          }
        }
        if (!debug_dir.empty())
          write_text_atomically(fs::path(debug_dir) / (std::to_string(i + 1) + "_" + spec.name) / "stage.json",
                                sr.dump(2) + "\n");
        if (log) *log << "    done in " << std::fixed << std::setprecision(2) << secs << " s, peak "
                      << std::setprecision(0) << peak_memory_mib() << " MiB\n";
        run_report["stages"].push_back(sr);
      }
      {
        const std::vector<std::string> ran(available.begin() + first, available.begin() + last + 1);
        std::string rest;
        for (const auto& s : pipeline_stage_order())
          if (std::find(ran.begin(), ran.end(), s) == ran.end()) rest += (rest.empty() ? "" : ", ") + s;
        if (!rest.empty()) {
          run_report["not_run"] = rest;
          if (log) *log << "colonflat run: stopped after " << available[last] << " (not run: " << rest << ")\n";
        }
      }
      run_report["total_time_s"] = total.seconds();
      run_report["peak_memory_mib"] = peak_memory_mib();
      std::ostringstream txt;
      txt << "ColonFlat " << colonflat_version() << " run on " << input << " (units mm, LPS)\n";
      for (const auto& s : run_report["stages"])
        txt << "  " << std::left << std::setw(12) << s["stage"].get<std::string>() << std::fixed << std::setprecision(2)
            << s["time_s"].get<double>() << " s  " << s["result"].dump() << "\n";
      txt << "total " << std::setprecision(2) << total.seconds() << " s, peak " << std::setprecision(0)
          << peak_memory_mib() << " MiB\n";
      std::ofstream(tx.stage(fs::path(outdir) / "run_report.json")) << run_report.dump(2) << "\n";
      std::ofstream(tx.stage(fs::path(outdir) / "run_report.txt")) << txt.str();
      if (!params_out.empty()) std::ofstream(tx.stage(params_out)) << all_params.dump(2) << "\n";
      tx.commit();
      out << txt.str();
      // The review report (report module) once the last stage has run: report.html, polyps.mrk.json.
      // It reads the run folder; the in-memory artifacts are released first.
      bag = ArtifactBag();
      if (last + 1 == available.size())
        for (auto& t : registered_module_tools())
          if (t->name() == "report")
            return t->run(quiet ? std::vector<std::string>{outdir, "-q"} : std::vector<std::string>{outdir}, out, err);
      return kExitOk;
    });
  }

 private:
  // Without INPUT: the full phantom, seed 1, generated by the `phantom` command into OUTDIR/phantom.
  static std::string generate_default_input(const std::string& outdir, std::ostream& out, std::ostream& err,
                                            std::ostream* log) {
    for (auto& t : registered_module_tools()) {
      if (t->name() != "phantom") continue;
      const std::string dir = (fs::path(outdir) / "phantom").string();
      if (log) *log << "colonflat run: no INPUT; generating the full-size phantom (seed 1) into " << dir << "\n";
      std::ostringstream sink;
      const int rc = t->run({"-o", dir, "--seed", "1", "--size", "full"}, log ? *log : sink, err);
      if (rc != kExitOk) throw Error("phantom generation failed (exit " + std::to_string(rc) + ")");
      return (fs::path(dir) / "ct.nrrd").string();
    }
    throw UsageError("no INPUT given and this build has no phantom generator");
  }
};

}  // namespace

std::unique_ptr<Tool> make_run_tool() { return std::make_unique<RunTool>(); }

}  // namespace cf
