#pragma once
// load_mesh() with the outward orientation of the stages' reader (mesh_artifact()): closed
// components whose normals point into the lumen reversed on the file's face list (orientation.h),
// so that reversing an inward copy of a file gives back the outward file's triangles exactly
// (an OpenMesh face's vertex order may start at another corner than the file's).
#include <filesystem>

#include "colonflat/core/mesh_io.h"

namespace cf {

LoadedMesh load_mesh_oriented(const std::filesystem::path& path, const LoadPolicy& policy, bool outward);

}  // namespace cf
