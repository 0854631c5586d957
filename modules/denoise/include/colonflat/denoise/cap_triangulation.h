#pragma once
// Minimum-area triangulation of a closed 3D polygon (the caps of surgery).
#include <array>
#include <functional>
#include <vector>

#include "colonflat/core/mesh.h"

namespace cf {

// Minimum-area triangulation of a closed polygon (dynamic programming, O(n^3)); triangles
// (i, m, j) with i < m < j index `ring` and are oriented like the polygon, listed as ears: each
// triangle has two edges on the polygon left by removing the ones before it. With `allowed`, only
// triangles it accepts are used (called once per candidate that would improve a subproblem);
// empty result when no triangulation consists of allowed triangles.
std::vector<std::array<int, 3>> min_area_triangulation(const std::vector<Vec3>& ring,
                                                        const std::function<bool(int, int, int)>& allowed = {});

}  // namespace cf
