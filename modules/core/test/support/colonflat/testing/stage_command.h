#pragma once
// Runs a stage's stand-alone command (`colonflat <stage> ARGS...`) in-process from its factory and
// captures exit code and output; for module tests that do not link the pipeline.
#include <sstream>
#include <string>
#include <vector>

#include "colonflat/core/stage.h"

namespace cf::testing {

struct CommandResult {
  int code;
  std::string out, err;
};

inline CommandResult run_stage_command(const StageFactory& factory, const std::vector<std::string>& args) {
  auto tool = make_stage_tool(factory);
  std::ostringstream out, err;
  const int code = tool->run(args, out, err);
  return {code, out.str(), err.str()};
}

}  // namespace cf::testing
