#include "colonflat/core/tool.h"

#include <exception>
#include <ostream>

#include "colonflat/core/error.h"

namespace cf {

std::string colonflat_version() { return COLONFLAT_VERSION; }

std::string tool_help(CLI::App& app) { return app.help(); }

int run_cli(CLI::App& app, const std::string& tool, const std::vector<std::string>& args, std::ostream& out,
            std::ostream& err, const std::function<int()>& body) {
  const std::string prefix = "colonflat " + tool + ": error: ";
  try {
    std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 parses from the back
    app.parse(reversed);
  } catch (const CLI::CallForHelp&) {
    out << app.help();
    return kExitOk;
  } catch (const CLI::CallForAllHelp&) {
    out << app.help("", CLI::AppFormatMode::All);
    return kExitOk;
  } catch (const CLI::CallForVersion&) {
    out << "colonflat " << colonflat_version() << "\n";
    return kExitOk;
  } catch (const CLI::ParseError& e) {
    err << prefix << e.what() << " (see 'colonflat " << tool << " --help')\n";
    return kExitUsage;
  }
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
