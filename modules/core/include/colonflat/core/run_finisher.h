#pragma once
// A step that `colonflat run` performs after its last stage on the artifacts still in memory
// (the review report). A registered Tool that also derives RunFinisher is found by the run: its
// outputs are checked with the run's before any work, written into the run's staging folders
// and committed together with the stages' outputs, so a failing finisher leaves no run output.
#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colonflat/core/atomic_file.h"
#include "colonflat/core/stage.h"

namespace cf {

// What a finisher gets from the run.
struct FinishedRun {
  std::filesystem::path dir;                 // the run folder (the outputs' final place)
  std::string input;                         // the run's input file ("" when none)
  std::vector<std::string> stages;           // the stages run, in order
  const nlohmann::json* report = nullptr;    // run_report.json so far (stages, totals)
  ArtifactBag* artifacts = nullptr;          // every stage's outputs; a finisher may take() them
  std::ostream* log = nullptr;               // progress lines; null = quiet
};

class RunFinisher {
 public:
  virtual ~RunFinisher() = default;
  // Whether it runs after these stages (names in run order).
  virtual bool applies_to(const std::vector<std::string>& stages_run) const = 0;
  // The files it writes into `run_dir`, and the folders it replaces there (checked before the run
  // starts, with the run's other outputs).
  virtual std::vector<std::filesystem::path> planned_outputs(const std::filesystem::path& run_dir) const = 0;
  virtual std::vector<std::filesystem::path> planned_folders(const std::filesystem::path& run_dir) const = 0;
  // Called by the run right after each of its stages, on the run's thread, before the next stage
  // starts: `record` is the stage's run_report entry ({"stage", "result", ...}). A finisher may
  // start work on the artifacts there in the background (its own references, never changing the
  // bag), to be awaited in finish(); it must let go of them when that work ends, so that the run
  // can free or park them. Default: nothing.
  virtual void stage_done(const std::string& stage, const ArtifactBag& bag, const nlohmann::json& record) {
    (void)stage, (void)bag, (void)record;
  }
  // Writes them through `tx` (targets in run.dir; the run commits). Returns its record for
  // run_report.json: {"time_s", "phases", ...}. Throws cf::Error.
  virtual nlohmann::json finish(FinishedRun& run, OutputTransaction& tx) = 0;
};

}  // namespace cf
