#include "colonflat/core/candidate_list.h"

#include <cmath>

#include "colonflat/core/error.h"
#include "colonflat/core/stage.h"

namespace cf {
namespace {

// The first of `keys` present in `e`, as a finite 3-vector; nullopt when none is present or the
// first present one is malformed.
std::optional<std::array<double, 3>> position_of(const nlohmann::json& e) {
  for (const char* key : {"position_lps_mm", "center_lps_mm", "center", "position"}) {
    if (!e.contains(key)) continue;
    const auto& a = e[key];
    if (!a.is_array() || a.size() != 3 || !a[0].is_number() || !a[1].is_number() || !a[2].is_number())
      return std::nullopt;
    const std::array<double, 3> p{a[0].get<double>(), a[1].get<double>(), a[2].get<double>()};
    if (!std::isfinite(p[0] + p[1] + p[2])) return std::nullopt;
    return p;
  }
  return std::nullopt;
}

const nlohmann::json& entry_list(const nlohmann::json& doc, const std::string& name) {
  if (doc.is_array()) return doc;
  if (!doc.is_object()) throw InputError(name, "expected a candidate list or an object with \"candidates\"");
  for (const char* key : {"candidates", "polyps"})
    if (doc.contains(key) && doc[key].is_array()) return doc[key];
  throw InputError(name, "no \"candidates\" list");
}

}  // namespace

std::vector<CandidateEntry> candidate_list_from_json(const nlohmann::json& doc, const std::string& name) {
  const nlohmann::json& list = entry_list(doc, name);
  std::vector<CandidateEntry> out;
  for (std::size_t k = 0; k < list.size(); ++k) {
    const auto& e = list[k];
    const auto position = e.is_object() ? position_of(e) : std::nullopt;
    if (!position) throw InputError(name, "candidate " + std::to_string(k + 1) + " has no position_lps_mm [L, P, S]");
    CandidateEntry c;
    c.lps_mm = *position;
    c.id = e.contains("id") && e["id"].is_number_integer() ? e["id"].get<int>() : int(k + 1);
    for (const char* key : {"size_mm", "diameter_mm"})
      if (e.contains(key) && e[key].is_number()) {
        c.size_mm = e[key].get<double>();
        break;
      }
    if (e.contains("score") && e["score"].is_number()) c.score = e["score"].get<double>();
    out.push_back(c);
  }
  return out;
}

std::vector<CandidateEntry> read_candidate_list(const std::filesystem::path& path) {
  return candidate_list_from_json(read_json_file(path), path.string());
}

std::filesystem::path find_candidate_file(const std::filesystem::path& run_dir) {
  for (const char* file : {"candidates.json", "polyps.json"})
    if (std::filesystem::exists(run_dir / file)) return run_dir / file;
  return {};
}

}  // namespace cf
