#pragma once
// 3D Slicer Markups files (.mrk.json, schema markups-schema-v1.0.3): one point list ("Fiducial")
// with one control point per finding, coordinateSystem LPS, coordinateUnits mm, each point with
// its label (e.g. "P3") and a description (size, score, position along the colon).
#include <array>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace cf {

struct MarkupPoint {
  std::string label;                   // "P3"
  std::string description;             // free text
  std::array<double, 3> lps_mm{0, 0, 0};
};

// The schema URL written in "@schema".
const char* slicer_markups_schema_url();

// A Markups document with one point list named `name`, drawn in `rgb` (0..1 each).
nlohmann::json slicer_point_list(const std::string& name, const std::vector<MarkupPoint>& points,
                                 const std::array<double, 3>& rgb);

}  // namespace cf
