#pragma once
// A `colonflat <tool>` command is a library function over an argument vector (as in ANTs), so
// tests and the pipeline call it in-process. run_cli() gives every tool the same behaviour:
// --help to stdout with exit 0, one "colonflat <tool>: error: ..." line on stderr with the
// exit code of the error (error.h), never an error with exit 0.
#include <CLI/CLI.hpp>

#include <functional>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

namespace cf {

std::string colonflat_version();  // "0.1.0"

class Tool {
 public:
  virtual ~Tool() = default;
  virtual std::string name() const = 0;
  virtual std::string summary() const = 0;
  // `args` excludes the program and tool names. Returns the process exit code.
  virtual int run(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) = 0;
};

// Parses `args` into `app` and calls `body`; maps help, parse errors and exceptions to output
// and an exit code. `body` returns the exit code on success paths.
int run_cli(CLI::App& app, const std::string& tool, const std::vector<std::string>& args, std::ostream& out,
            std::ostream& err, const std::function<int()>& body);

// Formats CLI11 help with a heading; used by run_cli for --help.
std::string tool_help(CLI::App& app);

}  // namespace cf
