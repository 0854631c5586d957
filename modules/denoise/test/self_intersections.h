#pragma once
// Independent check for tests: CGAL's Polygon Mesh Processing counts pairs of faces that
// intersect other than along a shared vertex or edge.
#include <cstddef>

#include "colonflat/core/mesh.h"

namespace cf::testing {
std::size_t count_self_intersections(const Mesh& mesh);
}
