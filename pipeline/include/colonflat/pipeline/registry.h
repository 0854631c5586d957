#pragma once
// Every `colonflat` command and pipeline stage known to this build.
#include <memory>
#include <string>
#include <vector>

#include "colonflat/core/stage.h"
#include "colonflat/core/tool.h"

namespace cf {

// The order in which `colonflat run` chains the registered stages, derived from their ports: a
// stage comes after every stage that outputs one of its input ports (same port name); ties keep
// the registration (module) order. Throws cf::Error if the ports form a cycle.
const std::vector<std::string>& pipeline_stage_order();

// Generated from the modules' registrations (pipeline/CMakeLists.txt).
std::vector<std::unique_ptr<Tool>> registered_module_tools();
std::vector<StageFactory> registered_stage_factories();

// A factory for the named stage, or an empty function.
StageFactory find_stage(const std::string& name);

// All commands: info, run, every module tool and every stage's stand-alone command.
std::vector<std::unique_ptr<Tool>> all_tools();

std::unique_ptr<Tool> make_info_tool();
std::unique_ptr<Tool> make_run_tool();

}  // namespace cf
