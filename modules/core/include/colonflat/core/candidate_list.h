#pragma once
// The polyp candidate lists the stages exchange (contract 2): render's candidates.json
// ({"candidates": [...], ...}; called polyps.json before) and the phantom's truth polyps.json (a
// plain list, or {"polyps": [...]}). One reader for every consumer (register, report).
//
//   for (const cf::CandidateEntry& c : cf::read_candidate_list(dir / "candidates.json")) ...
#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace cf {

struct CandidateEntry {
  int id = 0;                          // "id"; else the 1-based place in the list
  std::array<double, 3> lps_mm{0, 0, 0};  // LPS mm: "position_lps_mm", else "center_lps_mm", "center", "position"
  double size_mm = 0;                  // "size_mm", else "diameter_mm"; 0 when absent
  std::optional<double> score;         // "score" (0..1); absent in truth lists
};

// The entries of a candidate or truth document. Throws InputError(name, ...) when the document is
// neither a list nor an object with a "candidates" (or "polyps") list, or when an entry is not an
// object with a finite [L, P, S] position ("candidate K has no position_lps_mm [L, P, S]").
std::vector<CandidateEntry> candidate_list_from_json(const nlohmann::json& doc, const std::string& name);

// read_json_file + candidate_list_from_json.
std::vector<CandidateEntry> read_candidate_list(const std::filesystem::path& path);

// A run folder's candidate file: DIR/candidates.json, else DIR/polyps.json (runs before the
// rename), else an empty path.
std::filesystem::path find_candidate_file(const std::filesystem::path& run_dir);

}  // namespace cf
