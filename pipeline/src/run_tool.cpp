// `colonflat run [INPUT] -o OUTDIR`: chains the stages in memory (pipeline_stage_order(): from their ports), then
// the finishers (the review report) on the artifacts still in memory. With `--prone PRONE`: both
// scans, then the register tool's pair step (registration, supine-prone review) on their memory. Everything is checked
// first (run_plan.cpp); outputs go to OUTDIR/.colonflat-staging-<pid>-<n>/ and are renamed into
// OUTDIR only when every stage and finisher succeeded.
#include <fstream>
#include <iomanip>
#include <sstream>

#include "colonflat/core/atomic_file.h"
#include "colonflat/core/error.h"
#include "colonflat/core/output_check.h"
#include "colonflat/core/pair_finisher.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/core/stage_runner.h"
#include "colonflat/pipeline/registry.h"
#include "artifact_parking.h"
#include "run_plan.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

class RunTool : public Tool {
 public:
  std::string name() const override { return "run"; }
  std::string summary() const override { return "the whole pipeline in memory: segment -> ... -> render"; }
  int run(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) override {
    std::string all;
    for (const auto& n : available_stages()) all += (all.empty() ? "" : ", ") + n;
    CLI::App app("Runs the stages of this build in order (" + all +
                     ") in memory. Without INPUT, generates the full-size phantom (seed 1) into OUTDIR/phantom "
                     "and runs on it. Outputs record units (mm) and coordinate system (LPS).",
                 "colonflat run");
    app.set_version_flag("--version", colonflat_version());
    RunOptions o;
    add_options(app, o, all);
    return run_cli(app, name(), args, out, err, [&]() -> int {
      std::ostream* log = o.quiet ? nullptr : &err;
      const PacsSession pacs(o, log);  // --pacs: the study retrieved into a temporary exam folder
      if (o.prone.empty()) resolve_exam_input(o, log, pacs.active());
      const int rc = o.prone.empty() ? run_one_scan(o, out, err) : run_two_scans(o, out, err);
      pacs.store_results(o, out);  // --store: only after the whole run succeeded
      return rc;
    });
  }

 private:
  static int run_one_scan(RunOptions& o, std::ostream& out, std::ostream& err) {
    RunPlan plan = plan_run(o);
    std::ostream* log = o.quiet ? nullptr : &err;
    if (plan.generate_input) o.input = generate_default_input(o.outdir, err, log);
    ArtifactBag bag;
    OutputTransaction tx;
    const nlohmann::json report = execute(plan, o, log, bag, tx);
    tx.commit();
    if (!o.quiet) out << run_summary_text(report, o.outdir);
    return kExitOk;
  }

  static void add_options(CLI::App& app, RunOptions& o, const std::string& all) {
    app.add_option("input", o.input,
                   "input of the first stage run (a CT volume, or with --from the file that stage reads); a DICOM "
                   "exam (folder of series as a PACS exports it, or its DICOMDIR): its supine and prone CT scans")
        ->type_name("FILE");
    app.add_option("-o,--output", o.outdir,
                   "output folder (default colonflat_out); refused when it holds the input or a phantom")
        ->type_name("DIR");
    app.add_option("--debug-dir", o.debug_dir, "also write every stage's outputs and a per-stage JSON here")
        ->type_name("DIR");
    app.add_option("--from", o.from, "first stage to run (" + all + ")")->type_name("STAGE");
    app.add_option("--to", o.to, "last stage to run")->type_name("STAGE");
    app.add_option("--params-in", o.params_in, "JSON {stage: {param: value}} of parameters")->type_name("FILE.json");
    app.add_option("--params-out", o.params_out, "write every effective parameter as JSON")->type_name("FILE.json");
    app.add_option("--set", o.sets, "set one parameter, e.g. --set denoise.max-loop-length=20 (repeatable)")
        ->type_name("STAGE.PARAM=VALUE");
    app.add_option("--prone", o.prone,
                   "two-scan mode: the prone scan of the same patient (INPUT is the supine one); both are run "
                   "into OUTDIR/supine and OUTDIR/prone, then registered into OUTDIR/registration")
        ->type_name("FILE");
    app.add_option("--pacs", o.pacs,
                   "retrieve the study from this PACS (C-GET) instead of INPUT, then run on it as on an exam folder")
        ->type_name("AET@HOST:PORT");
    app.add_option("--study", o.study, "with --pacs: the StudyInstanceUID to retrieve")->type_name("UID");
    app.add_flag("--store", o.store, "with --pacs: send the DICOM results (SEG, SR, SC) back (C-STORE) after the run");
    app.add_option("--aet", o.aet, "with --pacs: our own AE title (default COLONFLAT)")->type_name("AET");
    app.add_flag("-q,--quiet", o.quiet, "print nothing but errors");
  }

  // `--prone PRONE`: both scans planned (every check) before any work, each run in memory, then
  // the register tool's pair step (registration and review page) on both runs' memory; the
  // outputs of all three go through one transaction (nothing appears unless everything succeeded).
  static int run_two_scans(const RunOptions& o, std::ostream& out, std::ostream& err) {
    auto tools = registered_module_tools();
    PairFinisher* pair = nullptr;
    for (auto& t : tools)
      if (t->name() == "register") pair = dynamic_cast<PairFinisher*>(t.get());
    if (!pair) throw UsageError("--prone needs the register command, which this build lacks");
    if (o.input.empty()) throw UsageError("--prone needs INPUT, the supine scan");
    const fs::path outdir(o.outdir), regdir = outdir / "registration";
    RunOptions sup = o, pro = o;
    sup.prone = pro.prone = "";
    sup.outdir = (outdir / "supine").string();
    pro.outdir = (outdir / "prone").string();
    pro.input = o.prone;
    pro.params_out = "";  // the same parameters: written once
    if (!o.debug_dir.empty()) {
      sup.debug_dir = (fs::path(o.debug_dir) / "supine").string();
      pro.debug_dir = (fs::path(o.debug_dir) / "prone").string();
    }
    RunPlan sup_plan = plan_run(sup), pro_plan = plan_run(pro);
    if (sup_plan.stages.back()->spec().name != "render")
      throw UsageError("--prone: the run must go through render (registration reads flat maps and candidates)");
    PathPlan paths;
    paths.input(o.input);
    paths.input(o.prone);
    for (const auto& f : pair->pair_outputs(regdir)) paths.output(f, "-o (registration)");
    for (const auto& d : pair->pair_folders(regdir)) paths.output_folder(d, "-o (registration)");
    paths.check();
    if (same_file(o.input, o.prone)) throw UsageError(o.prone + ": --prone is the same file as INPUT");
    std::ostream* log = o.quiet ? nullptr : &err;
    OutputTransaction tx;
    ArtifactBag sup_bag, pro_bag;
    if (log) *log << "colonflat run: supine scan " << o.input << " -> " << sup.outdir << "\n";
    const nlohmann::json sup_report = execute(sup_plan, sup, log, sup_bag, tx);
    if (log) *log << "colonflat run: prone scan " << o.prone << " -> " << pro.outdir << "\n";
    const nlohmann::json pro_report = execute(pro_plan, pro, log, pro_bag, tx);
    if (log) *log << "[after both scans] register: registration and review page -> " << regdir.string() << "\n";
    FinishedRun sup_run{sup.outdir, sup.input, {}, &sup_report, &sup_bag, log};
    FinishedRun pro_run{pro.outdir, pro.input, {}, &pro_report, &pro_bag, log};
    const nlohmann::json record = pair->finish_pair(sup_run, pro_run, regdir, tx);
    for (auto& t : tools)  // the other pair steps (the DICOM results' pairing) after the registration
      if (auto* other = dynamic_cast<PairFinisher*>(t.get()); other && other != pair)
        other->finish_pair(sup_run, pro_run, regdir, tx);
    tx.commit();
    if (!o.quiet) {
      for (const auto& w : record.value("warnings", nlohmann::json::array()))
        err << "colonflat register: warning: " << w.get<std::string>() << "\n";
      out << run_summary_text(sup_report, sup.outdir) << run_summary_text(pro_report, pro.outdir)
          << "registration: " << record["pairs"] << " candidate pairs, " << record["supine_only"] << " supine-only, "
          << record["prone_only"] << " prone-only in " << std::fixed << std::setprecision(1)
          << record["time_s"].get<double>() << " s (scans from memory " << record["timing_s"].value("scans_from_memory", 0.0)
          << ", register " << record["timing_s"].value("register", 0.0) << ", image and files "
          << record["timing_s"].value("image_and_files", 0.0) << ", review page " << record["timing_s"].value("review", 0.0)
          << " s) -> " << (regdir / "report.html").string() << "\n";
    }
    return kExitOk;
  }

  // The stages and finishers of one run; every output (run_report.json too) staged in `tx`, the
  // artifacts left in `bag`. The caller commits.
  static nlohmann::json execute(RunPlan& plan, const RunOptions& o, std::ostream* log, ArtifactBag& bag,
                                OutputTransaction& tx) {
    const Port& in_port = plan.stages.front()->spec().inputs.at(0);
    if (log) *log << "colonflat run: reading " << o.input << " as " << in_port.type->name << "\n";
    bag.put(in_port.name, in_port.type->read(o.input));
    nlohmann::json report = {{"version", colonflat_version()}, {"input", o.input},           {"units", "mm"},
                             {"coordinate_system", "LPS"},     {"stages", nlohmann::json::array()}};
    Stopwatch total;
    const nlohmann::json params = run_stages(plan, o, bag, tx, report, log);
    std::string rest;
    for (const auto& s : plan.not_run) rest += (rest.empty() ? "" : ", ") + s;
    if (!rest.empty()) report["not_run"] = rest;
    if (!o.exam.is_null()) report["exam"] = o.exam;
    report["stages_time_s"] = report["total_time_s"] = total.seconds();
    report["peak_memory_mib"] = peak_memory_mib();
    run_finishers(plan, o, bag, tx, report, log);
    report["total_time_s"] = total.seconds();
    report["peak_memory_mib"] = peak_memory_mib();
    const fs::path outdir(o.outdir);
    std::ofstream(tx.stage(outdir / "run_report.json")) << report.dump(2) << "\n";
    std::ofstream(tx.stage(outdir / "run_report.txt")) << run_report_text(report);
    if (!o.params_out.empty()) std::ofstream(tx.stage(o.params_out)) << params.dump(2) << "\n";
    return report;
  }

  // Every stage in order, its outputs staged in `tx`; returns every stage's parameters.
  static nlohmann::json run_stages(RunPlan& plan, const RunOptions& o, ArtifactBag& bag, OutputTransaction& tx,
                                   nlohmann::json& report, std::ostream* log) {
    const fs::path outdir(o.outdir);
    nlohmann::json all_params = nlohmann::json::object();
    // Each stage's files are written on a second thread while the next stage runs (the
    // artifacts stay in the bag unchanged); all are written before the finishers, which may take them.
    BackgroundOutputWriter writer;
    ParkedArtifacts parked;  // e.g. the CT in 16 bits from reconstruct to the review report, the meshes as triangle lists
    nlohmann::json parked_log = nlohmann::json::array();
    for (std::size_t i = 0; i < plan.stages.size(); ++i) {
      Stage& st = *plan.stages[i];
      if (log) *log << "[" << (i + 1) << "/" << plan.stages.size() << "] " << st.spec().name << ": " << st.spec().summary << "\n";
      RunContext ctx;
      ctx.log = log;
      ctx.input_released = [&](const std::string& port) { parked.park_released(plan, i, port, bag, parked_log); };
      nlohmann::json record = run_stage_recorded(st, bag, ctx);
      std::map<std::string, fs::path> targets;
      for (const Port& p : st.spec().outputs) targets[p.name] = outdir / p.file_name;
      for (auto& tool : plan.finishers) as_finisher(*tool).stage_done(st.spec().name, bag, record);
      parked.park_outputs(plan, i, bag, parked_log);
      PendingOutputs outputs = stage_outputs(st, bag, targets, tx);
      record["outputs"] = outputs.files;
      writer.submit(std::move(outputs));
      parked.park_unread(plan, i, bag, parked_log);
      if (!o.debug_dir.empty()) write_debug(st, bag, record, fs::path(o.debug_dir) / (std::to_string(plan.first_index + i + 1) + "_" + st.spec().name), tx);
      all_params[st.spec().name] = st.params_json();
      if (log) *log << "    done in " << std::fixed << std::setprecision(2) << record["time_s"].get<double>()
                    << " s, peak " << std::setprecision(0) << peak_memory_mib() << " MiB\n";
      report["stages"].push_back(record);
    }
    writer.wait();
    if (!parked_log.empty()) report["held_compact"] = parked_log;
    return all_params;
  }

  // The finishers (review report) on the run's memory; their outputs staged with the stages'.
  static void run_finishers(RunPlan& plan, const RunOptions& o, ArtifactBag& bag, OutputTransaction& tx,
                            nlohmann::json& report, std::ostream* log) {
    if (plan.finishers.empty()) return;
    FinishedRun run;
    run.dir = o.outdir;
    run.input = o.input;
    for (const auto& st : plan.stages) run.stages.push_back(st->spec().name);
    run.report = &report;
    run.artifacts = &bag;
    run.log = log;
    nlohmann::json records = nlohmann::json::array();
    for (auto& tool : plan.finishers) {
      if (log) *log << "[after the stages] " << tool->name() << ": " << tool->summary() << "\n";
      nlohmann::json record = as_finisher(*tool).finish(run, tx);
      if (log) *log << "    done in " << std::fixed << std::setprecision(2) << record.value("time_s", 0.0) << " s\n";
      records.push_back(record);
    }
    report["after_stages"] = records;
  }

  static void write_debug(const Stage& st, const ArtifactBag& bag, const nlohmann::json& record, const fs::path& dir,
                          OutputTransaction& tx) {
    nlohmann::json copy = record;
    std::map<std::string, fs::path> targets;
    for (const Port& p : st.spec().outputs) targets[p.name] = dir / p.file_name;
    write_stage_outputs(st, bag, targets, tx, copy);
    std::ofstream(tx.stage(dir / "stage.json")) << copy.dump(2) << "\n";
  }

  // Without INPUT: the full phantom, seed 1, generated by the `phantom` command into OUTDIR/phantom.
  static std::string generate_default_input(const std::string& outdir, std::ostream& err, std::ostream* log) {
    for (auto& t : registered_module_tools()) {
      if (t->name() != "phantom") continue;
      const std::string dir = (fs::path(outdir) / "phantom").string();
      if (log) *log << "colonflat run: no INPUT; generating the full-size phantom (seed 1) into " << dir << "\n";
      std::ostringstream sink;
      std::vector<std::string> args = {"-o", dir, "--seed", "1", "--size", "full"};
      if (!log) args.push_back("-q");
      const int rc = t->run(args, log ? *log : sink, err);
      if (rc != kExitOk) throw Error("phantom generation failed (exit " + std::to_string(rc) + ")");
      return (fs::path(dir) / "ct.nrrd").string();
    }
    throw UsageError("no INPUT given and this build has no phantom generator");
  }
};

}  // namespace

std::unique_ptr<Tool> make_run_tool() { return std::make_unique<RunTool>(); }

}  // namespace cf
