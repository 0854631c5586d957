#include "colonflat/report/slicer_markups.h"

namespace cf {

const char* slicer_markups_schema_url() {
  return "https://raw.githubusercontent.com/slicer/slicer/master/Modules/Loadable/Markups/Resources/Schema/"
         "markups-schema-v1.0.3.json#";
}

nlohmann::json slicer_point_list(const std::string& name, const std::vector<MarkupPoint>& points,
                                 const std::array<double, 3>& rgb) {
  nlohmann::json cps = nlohmann::json::array();
  for (std::size_t i = 0; i < points.size(); ++i)
    cps.push_back({{"id", std::to_string(i + 1)},
                   {"label", points[i].label},
                   {"description", points[i].description},
                   {"associatedNodeID", ""},
                   {"position", points[i].lps_mm},
                   {"orientation", {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0}},
                   {"selected", true},
                   {"locked", true},
                   {"visibility", true},
                   {"positionStatus", "defined"}});
  nlohmann::json display = {{"visibility", true},
                            {"opacity", 1.0},
                            {"color", rgb},
                            {"selectedColor", rgb},
                            {"pointLabelsVisibility", true},
                            {"textScale", 3.0},
                            {"glyphType", "Sphere3D"},
                            {"glyphSize", 4.0},
                            {"useGlyphScale", false}};
  nlohmann::json markup = {{"type", "Fiducial"},
                           {"name", name},
                           {"coordinateSystem", "LPS"},
                           {"coordinateUnits", "mm"},
                           {"locked", true},
                           {"labelFormat", "%N-%d"},
                           {"controlPoints", cps},
                           {"display", display}};
  return {{"@schema", slicer_markups_schema_url()}, {"markups", nlohmann::json::array({markup})}};
}

}  // namespace cf
