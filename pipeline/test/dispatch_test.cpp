// The dispatcher: help, version, unknown commands and exit codes.
#include <gtest/gtest.h>

#include <sstream>

#include "colonflat/pipeline/dispatch.h"
#include "colonflat/testing/command.h"

namespace cf {
namespace {

testing::CommandResult call(const std::vector<std::string>& args) { return testing::run_colonflat(args); }

// --help lists the commands and exits 0; no arguments is a usage error (2).
TEST(Dispatch, HelpListsCommands) {
  auto r = call({"--help"});
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("info"), std::string::npos);
  EXPECT_NE(r.out.find("run"), std::string::npos);
  EXPECT_EQ(call({}).code, 2);
}

// --version prints the version.
TEST(Dispatch, Version) {
  auto r = call({"--version"});
  EXPECT_EQ(r.code, 0);
  EXPECT_EQ(r.out.rfind("colonflat ", 0), 0u);
}

// An unknown command is one error line and exit 2.
TEST(Dispatch, UnknownCommand) {
  auto r = call({"frobnicate"});
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "colonflat: error: unknown command 'frobnicate' (see 'colonflat --help')\n");
}

// Every command answers --help with exit 0 and its own usage.
TEST(Dispatch, EveryCommandHasHelp) {
  auto list = call({"--help"}).out;
  std::istringstream in(list);
  std::string line;
  int seen = 0;
  bool in_commands = false;
  while (std::getline(in, line)) {
    if (line == "commands:") {
      in_commands = true;
      continue;
    }
    if (!in_commands || line.size() < 3 || line[0] != ' ') continue;
    std::string name = line.substr(2, line.find(' ', 2) - 2);
    auto r = call({name, "--help"});
    EXPECT_EQ(r.code, 0) << name;
    EXPECT_NE(r.out.find("colonflat " + name), std::string::npos) << name << ": " << r.out;
    ++seen;
  }
  EXPECT_GE(seen, 2);
}

}  // namespace
}  // namespace cf
