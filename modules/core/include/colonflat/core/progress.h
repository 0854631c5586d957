#pragma once
// Phase progress: short lines such as "flatten: conformal map 3.1 s" on the command's progress
// stream while a long step runs, and the same times in its report.
//
//   ProgressScope scope(log, "flatten");   // the stage runner (or a tool) opens one per step
//   ...; phase_done("conformal map");      // code anywhere below calls this at each phase's end
//   scope.phases();                         // [{"phase": "conformal map", "time_s": 3.1}, ...]
//
// phase_done() reports the time since the previous phase_done() of the innermost open scope
// (or since the scope opened). Without an open scope it does nothing, so library functions can
// call it unconditionally; with a null log the times are still recorded. Thread-safe.
#include <ostream>
#include <string>

#include <nlohmann/json.hpp>

#include "colonflat/core/run_stats.h"

namespace cf {

class ProgressScope {
 public:
  // `log`: where the lines go (null: nowhere); `step`: the line prefix ("flatten").
  ProgressScope(std::ostream* log, std::string step);
  ~ProgressScope();
  ProgressScope(const ProgressScope&) = delete;
  ProgressScope& operator=(const ProgressScope&) = delete;
  // The phases reported so far, in order: [{"phase", "time_s"}].
  nlohmann::json phases() const;

 private:
  friend void phase_done(const std::string& phase);
  std::ostream* log_;
  std::string step_;
  Stopwatch since_last_;
  nlohmann::json phases_ = nlohmann::json::array();
  ProgressScope* outer_ = nullptr;
};

// Ends a phase of the innermost open ProgressScope: records its time and prints
// "<step>: <phase> <seconds> s".
void phase_done(const std::string& phase);

// Writes one line to `log` (if not null) under the lock shared by every progress writer, so
// lines from a heartbeat thread and from phases never interleave.
void write_progress_line(std::ostream* log, const std::string& line);

}  // namespace cf
