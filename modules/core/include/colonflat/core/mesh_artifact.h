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
// accepted, polygons triangulated, orientation made consistent); writes via write_mesh().
const ArtifactType& mesh_artifact();

nlohmann::json topology_to_json(const TopologyReport& t);
nlohmann::json diagnosis_to_json(const MeshDiagnosis& d);
// Human-readable report, one fact per line.
std::string topology_to_text(const TopologyReport& t);

}  // namespace cf
