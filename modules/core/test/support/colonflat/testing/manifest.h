#pragma once
// ../shared/meshes/MANIFEST.tsv as rows of column name -> value.
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace cf::testing {

using ManifestRow = std::map<std::string, std::string>;

inline std::vector<ManifestRow> read_mesh_manifest() {
  std::vector<ManifestRow> rows;
  std::ifstream in(std::filesystem::path(COLONFLAT_SHARED_DIR) / "meshes" / "MANIFEST.tsv");
  auto split = [](const std::string& s) {
    std::vector<std::string> v;
    std::stringstream ss(s);
    std::string x;
    while (std::getline(ss, x, '\t')) v.push_back(x);
    return v;
  };
  std::string line;
  if (!std::getline(in, line)) return rows;
  const std::vector<std::string> head = split(line);
  while (std::getline(in, line)) {
    const auto v = split(line);
    ManifestRow r;
    for (std::size_t i = 0; i < head.size() && i < v.size(); ++i) r[head[i]] = v[i];
    rows.push_back(std::move(r));
  }
  return rows;
}

}  // namespace cf::testing
