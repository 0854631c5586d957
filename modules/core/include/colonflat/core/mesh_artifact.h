#pragma once
// The "mesh" artifact (triangle surface in LPS mm) and topology reports as JSON and text.
#include <nlohmann/json.hpp>

#include <string>

#include "colonflat/core/mesh.h"
#include "colonflat/core/stage.h"
#include "colonflat/core/topology.h"
#include "colonflat/core/validation.h"

namespace cf {

// Reads any supported mesh file through load_mesh() (boundaries and several components
// accepted, polygons triangulated, orientation made consistent and outward: what was turned or
// reversed is kept in the mesh property kReadOrientationProperty); writes via write_mesh().
const ArtifactType& mesh_artifact();

// Name of the mesh property in which mesh_artifact()'s reader leaves the faces it turned (an
// OrientationReport as JSON) for the stage to report.
inline constexpr const char* kReadOrientationProperty = "colonflat:read_orientation";

// A stage's first step on an input mesh `port` of `bag` (the one place stages orient meshes):
// reports what the reader turned or reversed, reverses every closed component whose normals still
// point into the lumen (orient_outward, orientation.h: a mesh not read from a file) in the bag, prints one progress line per changed
// component ("<stage>: <port>: component 0 (...): normals pointed into the lumen; reversed")
// and returns the report entry (OrientationReport::to_json()). `topology` (optional) receives
// the mesh's analyze_topology, computed on the way (orient_outward).
nlohmann::json orient_mesh_input(ArtifactBag& bag, const std::string& port, const RunContext& ctx,
                                 const std::string& stage, TopologyReport* topology = nullptr);

nlohmann::json topology_to_json(const TopologyReport& t);
nlohmann::json diagnosis_to_json(const MeshDiagnosis& d);
// Human-readable report, one fact per line.
std::string topology_to_text(const TopologyReport& t);

}  // namespace cf
