#pragma once
// `colonflat run` in three parts: plan (run_plan.cpp: every check before the first stage),
// execute (run_tool.cpp), summarise (run_summary.cpp). Internal to the pipeline library.
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colonflat/core/run_finisher.h"
#include "colonflat/core/stage.h"

namespace cf {

struct RunOptions {
  std::string input, outdir = "colonflat_out", debug_dir, from, to, params_in, params_out;
  std::string prone;  // two-scan mode: the prone scan of the same patient (INPUT is the supine one)
  std::vector<std::string> sets;
  bool quiet = false;
  // PACS round trip: --pacs AET@HOST:PORT --study UID [--store] [--aet OWN]
  std::string pacs, study, aet = "COLONFLAT";
  bool store = false;
  // INPUT was a DICOM exam (run_exam.cpp): the series chosen and why the others were not; copied
  // into run_report.json as "exam".
  nlohmann::json exam;
};

// The stages of one run, their parameters applied and checked, the chain of ports checked, and
// every output path checked against the inputs and each other.
struct RunPlan {
  std::vector<std::unique_ptr<Stage>> stages;  // in run order
  std::vector<std::string> not_run;            // pipeline stages outside --from/--to or not built
  std::size_t first_index = 0;                 // of stages[0] in the pipeline order (debug folders)
  bool generate_input = false;                 // no INPUT: the phantom is generated first
  // Registered tools that finish this run on its memory (the review report), in registry order.
  std::vector<std::unique_ptr<Tool>> finishers;
};

// The finisher interface of a planned finisher tool.
RunFinisher& as_finisher(Tool& tool);

// Validates the whole run (stage range, parameters, port chain and types, input file, output
// paths) and throws UsageError/InputError naming the first problem. Does no work and writes nothing.
RunPlan plan_run(RunOptions& options);

// `colonflat run EXAM` (run_exam.cpp): when INPUT is a DICOM exam (a DICOMDIR, a folder with DICOM
// files in subfolders, or a folder holding several series), chooses its CT colonography scans,
// prints the choice to `log`, and sets o.input (and o.prone for a supine + prone exam) to the
// chosen series and o.exam to the record. Returns false (changing nothing) for any other INPUT.
// With `force`, INPUT is taken as an exam even when it is a flat folder of one series (a study
// retrieved from a PACS).
bool resolve_exam_input(RunOptions& o, std::ostream* log, bool force = false);

// `colonflat run --pacs AET@HOST:PORT --study UID -o OUT [--store]` (run_pacs.cpp): the
// constructor checks the options and retrieves the study into a temporary folder (o.input), which
// the destructor removes; store_results() sends the run's DICOM results (OUT/dicom/, or
// OUT/supine/dicom/ and OUT/prone/dicom/) back with C-STORE after the run succeeded. Without
// --pacs it does nothing.
class PacsSession {
 public:
  PacsSession(RunOptions& o, std::ostream* log);
  ~PacsSession();
  PacsSession(const PacsSession&) = delete;
  PacsSession& operator=(const PacsSession&) = delete;
  bool active() const { return !folder_.empty(); }
  void store_results(const RunOptions& o, std::ostream& out) const;

 private:
  std::filesystem::path folder_;
  std::ostream* log_;
};

// The stage names of this build in pipeline order.
std::vector<std::string> available_stages();

// run_report.txt: a table of stages (time, memory, key results) and the totals.
std::string run_report_text(const nlohmann::json& run_report);
// The few lines `run` prints at the end: segments, genus before/after, loops cut, coverage,
// candidates, where the image is.
std::string run_summary_text(const nlohmann::json& run_report, const std::string& outdir);

}  // namespace cf
