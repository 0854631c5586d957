#pragma once
// A step that `colonflat run SUPINE --prone PRONE -o OUT` performs after both scans ran, on the
// memory of both runs (the supine-prone registration and its review page). A registered Tool that
// also derives PairFinisher is found by the run; its outputs are checked with the runs' before any
// work and staged in the same transaction as both runs' outputs, so everything appears together
// or, when any step fails, nothing does.
#include <filesystem>
#include <vector>

#include <nlohmann/json.hpp>

#include "colonflat/core/atomic_file.h"
#include "colonflat/core/run_finisher.h"

namespace cf {

class PairFinisher {
 public:
  virtual ~PairFinisher() = default;
  // The files and folders it writes into `dir` (checked before the runs start).
  virtual std::vector<std::filesystem::path> pair_outputs(const std::filesystem::path& dir) const = 0;
  virtual std::vector<std::filesystem::path> pair_folders(const std::filesystem::path& dir) const = 0;
  // Writes them through `tx` (targets in `dir`; the run commits). `supine` and `prone` hold each
  // run's folder, report and artifacts (the run's finishers may have taken some; see report's
  // kRunDataArtifact). Returns its record for the summary. Throws cf::Error.
  virtual nlohmann::json finish_pair(FinishedRun& supine, FinishedRun& prone, const std::filesystem::path& dir,
                                     OutputTransaction& tx) = 0;
};

}  // namespace cf
