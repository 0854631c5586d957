#pragma once
// Runs a shell command in a test (an external checker such as dciodvfy, storescu, curl, a Python
// reader) and returns its exit status with everything it printed (stdout and stderr).
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>
#include <utility>

namespace cf::testing {

inline std::pair<int, std::string> shell(const std::string& command) {
  std::string out;
  FILE* p = ::popen((command + " 2>&1").c_str(), "r");
  if (!p) return {-1, ""};
  std::array<char, 4096> buf{};
  for (std::size_t n; (n = std::fread(buf.data(), 1, buf.size(), p)) > 0;) out.append(buf.data(), n);
  const int status = ::pclose(p);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

}  // namespace cf::testing
