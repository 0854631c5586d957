#pragma once
// Small file helpers for tests: a file's bytes, and the files below a folder.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>
#include <vector>

namespace cf::testing {

// The whole file as bytes ("" when it cannot be read).
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// Every file below `dir` (recursively), as sorted paths relative to it; empty when `dir` is absent.
inline std::vector<std::string> listing(const std::filesystem::path& dir) {
  std::vector<std::string> v;
  std::error_code ec;
  if (!std::filesystem::exists(dir, ec)) return v;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir))
    v.push_back(e.path().lexically_relative(dir).string());
  std::sort(v.begin(), v.end());
  return v;
}

}  // namespace cf::testing
