#include "colonflat/pipeline/dispatch.h"

#include <iomanip>
#include <ostream>

#include "colonflat/core/error.h"
#include "colonflat/pipeline/registry.h"

namespace cf {

const std::vector<std::string>& pipeline_stage_order() {
  static const std::vector<std::string> order{"segment", "reconstruct", "denoise", "flatten", "render"};
  return order;
}

StageFactory find_stage(const std::string& name) {
  for (auto& f : registered_stage_factories())
    if (f()->spec().name == name) return f;
  return {};
}

std::vector<std::unique_ptr<Tool>> all_tools() {
  std::vector<std::unique_ptr<Tool>> v;
  v.push_back(make_info_tool());
  for (auto& t : registered_module_tools()) v.push_back(std::move(t));
  for (auto& f : registered_stage_factories()) v.push_back(make_stage_tool(f));
  v.push_back(make_run_tool());
  return v;
}

namespace {
void usage(std::ostream& out, const std::vector<std::unique_ptr<Tool>>& tools) {
  out << "colonflat " << colonflat_version()
      << " - CT colonography: segment, reconstruct, denoise topology, flatten, render\n\n"
         "usage: colonflat <command> [options]     (colonflat <command> --help for its options)\n\n"
         "commands:\n";
  for (const auto& t : tools) out << "  " << std::left << std::setw(13) << t->name() << t->summary() << "\n";
  out << "\nexit codes: 0 ok, 1 processing failed, 2 usage error, 3 bad input\n";
}
}  // namespace

int colonflat_main(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  auto tools = all_tools();
  if (args.empty() || args[0] == "-h" || args[0] == "--help" || args[0] == "help") {
    usage(out, tools);
    return args.empty() ? kExitUsage : kExitOk;
  }
  if (args[0] == "--version" || args[0] == "version") {
    out << "colonflat " << colonflat_version() << "\n";
    return kExitOk;
  }
  for (auto& t : tools)
    if (t->name() == args[0]) return t->run(std::vector<std::string>(args.begin() + 1, args.end()), out, err);
  err << "colonflat: error: unknown command '" << args[0] << "' (see 'colonflat --help')\n";
  return kExitUsage;
}

}  // namespace cf
