#pragma once
// The "loops" artifact: the loops cut by denoising, as closed polylines in a .vtp file with cell
// data loop_id, iteration, length_mm, vertex_count, type (0 handle, 1 tunnel) and separating,
// point data input_vertex_id (-1 where the vertex was created by surgery), and field data
// Units = mm, CoordinateSystem = LPS.
#include <filesystem>
#include <vector>

#include "colonflat/core/stage.h"
#include "colonflat/denoise/denoise.h"

namespace cf {

using LoopSet = std::vector<LoopRecord>;

void write_loops(const LoopSet& loops, const std::filesystem::path& path);  // atomic
LoopSet read_loops(const std::filesystem::path& path);                      // InputError on failure
const ArtifactType& loops_artifact();

}  // namespace cf
