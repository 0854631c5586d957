#pragma once
// `colonflat <command> ...` as a function: tests call it in-process with an argument vector.
#include <iosfwd>
#include <string>
#include <vector>

namespace cf {

// `args` excludes the program name. Returns the exit code (see core/error.h).
int colonflat_main(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

}  // namespace cf
