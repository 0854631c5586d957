#include "colonflat/pipeline/dispatch.h"

#include <iomanip>
#include <ostream>
#include <set>

#include "colonflat/core/error.h"
#include "colonflat/pipeline/registry.h"
#include "colonflat/volume/volume_io.h"

namespace cf {
namespace {

// Whether stage `consumer` reads an artifact that stage `producer` writes (a port of the same name).
bool feeds(const StageSpec& producer, const StageSpec& consumer) {
  for (const Port& out : producer.outputs)
    for (const Port& in : consumer.inputs)
      if (out.name == in.name) return true;
  return false;
}

// Registered stages in topological order of their ports (a stage after every stage that makes one
// of its inputs); ties keep the registration order (module order).
std::vector<std::string> stage_order_from_ports() {
  std::vector<StageSpec> specs;
  for (auto& factory : registered_stage_factories()) specs.push_back(factory()->spec());
  std::vector<std::string> order;
  std::set<std::size_t> placed;
  while (placed.size() < specs.size()) {
    std::size_t next = specs.size();
    for (std::size_t i = 0; i < specs.size() && next == specs.size(); ++i) {
      if (placed.count(i)) continue;
      bool ready = true;
      for (std::size_t j = 0; j < specs.size() && ready; ++j)
        ready = j == i || placed.count(j) || !feeds(specs[j], specs[i]);
      if (ready) next = i;
    }
    if (next == specs.size()) throw Error("the registered stages' ports form a cycle: no run order");
    placed.insert(next);
    order.push_back(specs[next].name);
  }
  return order;
}

}  // namespace

const std::vector<std::string>& pipeline_stage_order() {
  static const std::vector<std::string> order = stage_order_from_ports();
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

// `colonflat help COMMAND` (= COMMAND --help) and `colonflat help --markdown STAGE` (the stage's
// parameter table in Markdown, as on its docs page).
int help_on(const std::vector<std::string>& args, std::vector<std::unique_ptr<Tool>>& tools, std::ostream& out,
            std::ostream& err) {
  const bool markdown = args[1] == "--markdown";
  if (args.size() != (markdown ? 3u : 2u)) {
    err << "colonflat help: error: usage: colonflat help [--markdown] COMMAND\n";
    return kExitUsage;
  }
  const std::string& name = args.back();
  if (markdown) {
    const StageFactory factory = find_stage(name);
    if (!factory) {
      err << "colonflat help: error: '" << name << "' is not a pipeline stage (no parameter table)\n";
      return kExitUsage;
    }
    out << param_markdown(factory()->params());
    return kExitOk;
  }
  for (auto& t : tools)
    if (t->name() == name) return t->run({"--help"}, out, err);
  err << "colonflat help: error: unknown command '" << name << "' (see 'colonflat --help')\n";
  return kExitUsage;
}
}  // namespace

int colonflat_main(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  itk_follows_thread_count();  // --threads bounds ITK's pool too
  auto tools = all_tools();
  if (args.size() > 1 && args[0] == "help") return help_on(args, tools, out, err);
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
