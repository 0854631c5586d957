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

// The stage names of this build in pipeline order.
std::vector<std::string> available_stages();

// run_report.txt: a table of stages (time, memory, key results) and the totals.
std::string run_report_text(const nlohmann::json& run_report);
// The few lines `run` prints at the end: segments, genus before/after, loops cut, coverage,
// candidates, where the image is.
std::string run_summary_text(const nlohmann::json& run_report, const std::string& outdir);

}  // namespace cf
