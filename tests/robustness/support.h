#pragma once
// Helpers of the robustness suite (ctest label `robustness`): tiny generated inputs, file
// snapshots, leftover detection and the one-line error check.
#include <grp.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <sstream>
#include <fstream>
#include <iterator>
#include <regex>
#include <string>
#include <vector>

#include "colonflat/core/mesh_io.h"
#include "colonflat/core/output_check.h"
#include "colonflat/core/synthetic.h"
#include "colonflat/pipeline/dispatch.h"
#include "colonflat/pipeline/registry.h"
#include "colonflat/testing/command.h"
#include "colonflat/testing/files.h"
#include "colonflat/testing/temp_dir.h"

namespace cf::robust {

namespace fs = std::filesystem;
using testing::CommandResult;

inline CommandResult colonflat(const std::vector<std::string>& args) { return testing::run_colonflat(args); }

using testing::slurp;

inline void spit(const fs::path& p, const std::string& s) { std::ofstream(p, std::ios::binary) << s; }

using testing::listing;  // every file below a folder, relative to it

// Runs `colonflat ARGS` in a child process with the rights of the user nobody (uid and gid
// 65534), so that folder permissions apply when the tests run as root (root ignores them). The
// child reports its exit code and output through a pipe; code 125 when it cannot drop its rights.
inline CommandResult colonflat_as_nobody(const std::vector<std::string>& args) {
  int fd[2];
  if (::pipe(fd) != 0) return {125, "", "pipe failed"};
  const pid_t child = ::fork();
  if (child == 0) {
    ::close(fd[0]);
    CommandResult r{125, "", "cannot drop privileges to nobody"};
    if (::setgroups(0, nullptr) == 0 && ::setgid(65534) == 0 && ::setuid(65534) == 0) r = colonflat(args);
    const std::string payload = std::to_string(r.code) + "\n" + std::to_string(r.out.size()) + "\n" + r.out + r.err;
    for (std::size_t done = 0; done < payload.size();) {
      const ssize_t n = ::write(fd[1], payload.data() + done, payload.size() - done);
      if (n <= 0) break;
      done += std::size_t(n);
    }
    ::_exit(0);
  }
  ::close(fd[1]);
  std::string payload;
  char buf[4096];
  for (ssize_t n; (n = ::read(fd[0], buf, sizeof buf)) > 0;) payload.append(buf, std::size_t(n));
  ::close(fd[0]);
  ::waitpid(child, nullptr, 0);
  std::istringstream in(payload);
  CommandResult r{125, "", ""};
  std::size_t out_size = 0;
  in >> r.code >> out_size;
  in.get();
  const std::string rest(std::istreambuf_iterator<char>(in), {});
  r.out = rest.substr(0, out_size);
  r.err = rest.substr(std::min(out_size, rest.size()));
  return r;
}

// Hidden temporaries or staging folders below `dir`.
inline std::vector<std::string> leftovers(const fs::path& dir) {
  std::vector<std::string> v;
  for (const auto& f : listing(dir))
    if (f.find(".tmp-") != std::string::npos || f.find(".colonflat-staging-") != std::string::npos) v.push_back(f);
  return v;
}

// Exactly one line on stderr, "colonflat <cmd>: error: ...", containing `needle`.
inline ::testing::AssertionResult one_error_line(const CommandResult& r, const std::string& cmd,
                                                  const std::string& needle = "") {
  const std::string prefix = "colonflat " + cmd + ": error: ";
  const auto lines = std::count(r.err.begin(), r.err.end(), '\n');
  if (lines != 1 || r.err.rfind(prefix, 0) != 0)
    return ::testing::AssertionFailure() << "expected one line '" << prefix << "...', got: " << r.err;
  if (!needle.empty() && r.err.find(needle) == std::string::npos)
    return ::testing::AssertionFailure() << "error line lacks '" << needle << "': " << r.err;
  return ::testing::AssertionSuccess();
}

// A closed genus-1 torus mesh written as `name` in `dir` (any mesh format by extension).
inline fs::path torus_file(const testing::TempDir& dir, const std::string& name) {
  const fs::path p = dir / name;
  write_mesh(synthetic::to_mesh(synthetic::torus(10, 3, 16, 8)), p);
  return p;
}

}  // namespace cf::robust
