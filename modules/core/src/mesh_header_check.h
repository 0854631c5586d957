#pragma once
// Sizes a mesh file declares (vertex/face counts in OFF, PLY, binary STL, VTK legacy and VTK XML
// headers) checked against the file's size and the memory budget before any reader allocates.
// Only the header is looked at; the readers (OpenMesh, VTK) still parse the file.
#include <filesystem>

#include "colonflat/core/mesh_io.h"

namespace cf {

// Throws InputError with the declared counts and sizes when the file cannot hold what its header
// declares or when it would exceed the memory budget.
void check_declared_mesh_size(const std::filesystem::path& path, MeshFormat format);

// Text meshes (ASCII OFF, OBJ, ASCII PLY; other formats are skipped): throws InputError naming
// the first vertex with a coordinate that is not a finite number ("vertex 3 has a coordinate that
// is not a finite number: y = nan"). Parses the file only when it mentions "nan" or "inf".
void check_text_vertex_coordinates(const std::filesystem::path& path, MeshFormat format);

}  // namespace cf
