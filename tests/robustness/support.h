#pragma once
// Helpers of the robustness suite (ctest label `robustness`): tiny generated inputs, file
// snapshots, leftover detection and the one-line error check.
#include <gtest/gtest.h>

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
#include "colonflat/testing/temp_dir.h"

namespace cf::robust {

namespace fs = std::filesystem;
using testing::CommandResult;

inline CommandResult colonflat(const std::vector<std::string>& args) { return testing::run_colonflat(args); }

inline std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

inline void spit(const fs::path& p, const std::string& s) { std::ofstream(p, std::ios::binary) << s; }

// Every file below `dir` (recursively), as paths relative to it.
inline std::vector<std::string> listing(const fs::path& dir) {
  std::vector<std::string> v;
  std::error_code ec;
  if (!fs::exists(dir, ec)) return v;
  for (const auto& e : fs::recursive_directory_iterator(dir)) v.push_back(e.path().lexically_relative(dir).string());
  std::sort(v.begin(), v.end());
  return v;
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
