#include "colonflat/core/tool.h"

#include <cstring>
#include <exception>
#include <ostream>

#include "colonflat/core/error.h"
#include "colonflat/core/threads.h"

namespace cf {

std::string colonflat_version() { return COLONFLAT_VERSION; }

namespace {
// CLI11 shows the default of a negated flag ("--fluid,!--no-fluid") as "{false}": a parser
// leftover that means nothing to a reader; the help text states the default itself.
std::string clean_help(std::string help) {
  for (const char* junk : {"{false}", "{true}"})
    for (auto at = help.find(junk); at != std::string::npos; at = help.find(junk)) help.erase(at, std::strlen(junk));
  return help;
}
}  // namespace

std::string tool_help(CLI::App& app) { return clean_help(app.help()); }

int run_cli(CLI::App& app, const std::string& tool, const std::vector<std::string>& args, std::ostream& out,
            std::ostream& err, const std::function<int()>& body) {
  const std::string prefix = "colonflat " + tool + ": error: ";
  // Every command takes --threads (one place): the process-wide worker count, reset per command.
  int threads = 0;
  if (!app.get_option_no_throw("--threads"))
    app.add_option("--threads", threads, "worker threads (default: every core, or COLONFLAT_THREADS); results do not depend on it")
        ->check(CLI::Range(1, 1024))
        ->type_name("N");
  set_thread_count(0);
  try {
    std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 parses from the back
    app.parse(reversed);
  } catch (const CLI::CallForHelp&) {
    out << clean_help(app.help());
    return kExitOk;
  } catch (const CLI::CallForAllHelp&) {
    out << clean_help(app.help("", CLI::AppFormatMode::All));
    return kExitOk;
  } catch (const CLI::CallForVersion&) {
    out << "colonflat " << colonflat_version() << "\n";
    return kExitOk;
  } catch (const CLI::ParseError& e) {
    err << prefix << e.what() << " (see 'colonflat " << tool << " --help')\n";
    return kExitUsage;
  }
  set_thread_count(threads);
  try {
    return body();
  } catch (const Error& e) {
    err << prefix << e.what() << "\n";
    return e.exit_code();
  } catch (const std::bad_alloc&) {
    err << prefix << "out of memory\n";
    return kExitFailure;
  } catch (const std::exception& e) {
    err << prefix << "internal error: " << e.what() << "\n";
    return kExitFailure;
  }
}

}  // namespace cf
