#pragma once
// Runs `colonflat ARGS...` in-process (as the binary would) and captures exit code and output.
// Only for test targets that link colonflat_pipeline.
#include <sstream>
#include <string>
#include <vector>

#include "colonflat/pipeline/dispatch.h"
#include "colonflat/testing/stage_command.h"

namespace cf::testing {

inline CommandResult run_colonflat(const std::vector<std::string>& args) {
  std::ostringstream out, err;
  const int code = colonflat_main(args, out, err);
  return {code, out.str(), err.str()};
}

}  // namespace cf::testing
