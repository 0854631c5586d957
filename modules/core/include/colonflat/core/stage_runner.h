#pragma once
// The one stage runner: `colonflat <stage>` (stand-alone) and `colonflat run` (chained) both run a
// stage and write its outputs through these functions, so both produce the same report record.
//
// Stage record (the "stages" entries of run_report.json, and the whole --report of a stand-alone
// stage, which adds "version", "inputs" and "total_time_s"):
//   {"stage": "denoise", "parameters": {...}, "result": {...stage counts...},
//    "time_s": 1.23, "phases": [{"phase": "loop search", "time_s": 0.8}, ...],
//    "peak_memory_mib": 456, "outputs": {"denoised": "denoised.vtp", ...}}
#include <filesystem>
#include <functional>
#include <future>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colonflat/core/atomic_file.h"
#include "colonflat/core/output_check.h"
#include "colonflat/core/stage.h"

namespace cf {

// Runs `stage` on `bag` and returns its record (without "outputs"). While the stage runs, a line
// "    <stage>: still running (N s)" goes to ctx.log every `heartbeat_s` seconds, and a line
// "<stage>: <phase> N s" at every phase_done() (core/progress.h) of the stage's code; "phases"
// records those times. After the stage, the memory malloc holds free goes back to the kernel
// (release_free_memory, core/malloc_tunables.h).
nlohmann::json run_stage_recorded(Stage& stage, ArtifactBag& bag, RunContext& ctx, double heartbeat_s = 10.0);

// Writes the outputs of `stage` found in `targets` (port -> file) through `tx`; a missing
// required output is an Error. Adds "outputs": {port: file name} to `record`.
void write_stage_outputs(const Stage& stage, const ArtifactBag& bag,
                         const std::map<std::string, std::filesystem::path>& targets, OutputTransaction& tx,
                         nlohmann::json& record);

// The outputs of one stage, staged in `tx` (on the calling thread) but not yet written: `write`
// writes each file (safe on another thread while later stages run, as long as the artifacts stay
// in the bag unchanged); `files` is what write_stage_outputs adds to the record's "outputs".
struct PendingOutputs {
  std::vector<std::function<void()>> writes;
  nlohmann::json files = nlohmann::json::object();
  void write() const {
    for (const auto& w : writes) w();
  }
};
PendingOutputs stage_outputs(const Stage& stage, const ArtifactBag& bag,
                             const std::map<std::string, std::filesystem::path>& targets, OutputTransaction& tx);

// Writes one stage's outputs on a background thread while the next stage runs (`colonflat run`):
// one write job at a time, in stage order; a failed write is rethrown by the next submit() or by
// wait(). The destructor waits too (ignoring the error: the run is failing already).
class BackgroundOutputWriter {
 public:
  BackgroundOutputWriter() = default;
  BackgroundOutputWriter(const BackgroundOutputWriter&) = delete;
  BackgroundOutputWriter& operator=(const BackgroundOutputWriter&) = delete;
  ~BackgroundOutputWriter();
  void submit(PendingOutputs outputs);
  void wait();

 private:
  std::future<void> job_;
};

// Adds an output port's file to `plan`, with the extensions its type declares.
void plan_port_output(PathPlan& plan, const Port& port, const std::filesystem::path& file, const std::string& option);

// Checks that an input file exists and is readable (InputError otherwise); folders are accepted
// (DICOM series) when `folder_ok`.
void check_input_file(const std::filesystem::path& file, bool folder_ok);

}  // namespace cf
