#pragma once
// Internal to the denoise module: the pieces of a free-space cut (free_space_cut.cpp) that are
// disks (free_space_disks.cpp).
#include <array>
#include <cstddef>
#include <functional>
#include <vector>

#include "colonflat/denoise/free_space_cut.h"

namespace cf::detail {

// The connected pieces of `squares` (corners by lattice-vertex key, oriented; pieces joined by
// edges two squares share) that are disks: Euler characteristic 1, one boundary loop, no edge in
// more than two squares, every vertex's squares one fan. `point` gives a key's position; *pieces
// receives the number of pieces.
std::vector<CutDisk> cut_disks(const std::vector<std::array<long long, 4>>& squares,
                               const std::function<Vec3(long long)>& point, std::size_t* pieces);

}  // namespace cf::detail
