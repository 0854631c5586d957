#include "colonflat/core/stage_runner.h"

#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>

#include "colonflat/core/progress.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/core/malloc_tunables.h"
#include "colonflat/core/threads.h"

namespace fs = std::filesystem;

namespace cf {

namespace {

// Prints "still running" lines from a second thread until destroyed.
class Heartbeat {
 public:
  Heartbeat(const RunContext& ctx, std::string stage, double every_s)
      : ctx_(ctx), stage_(std::move(stage)), every_(std::chrono::duration<double>(every_s)) {
    if (ctx_.log && every_s > 0) thread_ = std::thread([this] { loop(); });
  }
  ~Heartbeat() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      done_ = true;
    }
    wake_.notify_all();
    if (thread_.joinable()) thread_.join();
  }

 private:
  void loop() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!wake_.wait_for(lock, every_, [this] { return done_; }))
      ctx_.progress("    " + stage_ + ": still running (" + std::to_string(int(clock_.seconds() + 0.5)) + " s)");
  }
  const RunContext& ctx_;
  std::string stage_;
  std::chrono::duration<double> every_;
  Stopwatch clock_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool done_ = false;
  std::thread thread_;
};

}  // namespace

void RunContext::progress(const std::string& line) const { write_progress_line(log, line); }

nlohmann::json run_stage_recorded(Stage& stage, ArtifactBag& bag, RunContext& ctx, double heartbeat_s) {
  Stopwatch clock;
  const double cpu0 = process_cpu_seconds();
  ProgressScope phases(ctx.log, stage.spec().name);
  {
    Heartbeat beat(ctx, stage.spec().name, heartbeat_s);
    stage.run(bag, ctx);
  }
  release_free_memory();  // what the stage freed goes back to the kernel (core/malloc_tunables.h)
  return {{"stage", stage.spec().name},
          {"parameters", stage.params_json()},
          {"result", ctx.report},
          {"time_s", clock.seconds()},
          {"cpu_time_s", process_cpu_seconds() - cpu0},
          {"threads", thread_count()},
          {"malloc_tunables", malloc_tunables()},
          {"phases", phases.phases()},
          {"peak_memory_mib", peak_memory_mib()},
          {"outputs", nlohmann::json::object()}};
}

PendingOutputs stage_outputs(const Stage& stage, const ArtifactBag& bag, const std::map<std::string, fs::path>& targets,
                             OutputTransaction& tx) {
  PendingOutputs out;
  for (const Port& p : stage.spec().outputs) {
    auto it = targets.find(p.name);
    if (it == targets.end() || it->second.empty()) continue;
    if (!bag.has(p.name)) {
      if (p.required) throw Error("stage " + stage.spec().name + " produced no '" + p.name + "' output");
      continue;
    }
    const std::any* value = &bag.raw(p.name);
    const fs::path tmp = tx.stage(it->second), target = it->second;
    const ArtifactType* type = p.type;
    out.writes.push_back([type, value, tmp, target] { type->write(*value, tmp, target); });
    out.files[p.name] = target.filename().string();
  }
  return out;
}

void write_stage_outputs(const Stage& stage, const ArtifactBag& bag, const std::map<std::string, fs::path>& targets,
                         OutputTransaction& tx, nlohmann::json& record) {
  const PendingOutputs out = stage_outputs(stage, bag, targets, tx);
  out.write();
  for (const auto& [port, file] : out.files.items()) record["outputs"][port] = file;
}

BackgroundOutputWriter::~BackgroundOutputWriter() {
  try {
    wait();
  } catch (...) {
  }
}

void BackgroundOutputWriter::submit(PendingOutputs outputs) {
  wait();
  job_ = std::async(std::launch::async, [o = std::move(outputs)] { o.write(); });
}

void BackgroundOutputWriter::wait() {
  if (job_.valid()) job_.get();
}

void plan_port_output(PathPlan& plan, const Port& port, const fs::path& file, const std::string& option) {
  plan.output(file, option, port.type->extensions);
}

void check_input_file(const fs::path& file, bool folder_ok) {
  std::error_code ec;
  const std::string name = file.string();
  if (name.empty()) throw UsageError("empty input path");
  if (!fs::exists(file, ec)) {
    // "DIR/SERIES_UID" names a DICOM series inside DIR.
    if (folder_ok && fs::is_directory(file.parent_path(), ec)) return;
    throw InputError(name, "no such file");
  }
  if (fs::is_directory(file, ec)) {
    if (!folder_ok) throw InputError(name, "is a folder, not a file");
    return;
  }
  if (::access(file.c_str(), R_OK) != 0) throw InputError(name, "cannot open for reading (permissions?)");
}

}  // namespace cf
