#pragma once
// Files written by `colonflat register` (docs/register.md):
//   OUT/registration.json   length alignment knots, twist, candidate pairs and singles, timings
//   OUT/supine_to_prone.vtp the supine flat map + per-vertex prone correspondence
//   OUT/prone_to_supine.vtp the prone flat map + per-vertex supine correspondence
//   OUT/supine_prone.png    the side-by-side image
#include <filesystem>

#include <nlohmann/json.hpp>
#include <vtkSmartPointer.h>

#include "colonflat/register/register.h"
#include "colonflat/register/side_by_side.h"

class vtkPolyData;

namespace cf {
class OutputTransaction;
}

namespace cf {

// The source scan's flat map with point data "<other>_vertex" (int, -1 = none),
// "<other>_flat_mm" (x, y, 0), "<other>_position_lps_mm", "register_s_mm", "register_angle_rad",
// "register_gap_mm" (mm along to the nearest supported alignment; 0 = supported, support.h).
vtkSmartPointer<vtkPolyData> correspondence_polydata(const ColonRegistration& reg, Direction d);

// Stages the four files for `dir` in `tx` (the caller commits; `dir` must exist or be staged).
void stage_registration(const ColonRegistration& reg, const std::filesystem::path& dir, const SideBySideOptions& image,
                        const nlohmann::json& params, OutputTransaction& tx);

// Writes the four files into `dir` (created if missing); all appear together or none.
// `params` is recorded in registration.json.
void write_registration(const ColonRegistration& reg, const std::filesystem::path& dir, const SideBySideOptions& image,
                        const nlohmann::json& params);

}  // namespace cf
