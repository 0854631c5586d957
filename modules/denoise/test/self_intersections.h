#pragma once
// Independent check for tests: CGAL's Polygon Mesh Processing counts pairs of faces that
// intersect other than along a shared vertex or edge.
#include <array>
#include <cstddef>
#include <utility>
#include <vector>

#include "colonflat/core/mesh.h"

namespace cf::testing {
std::size_t count_self_intersections(const Mesh& mesh);
// The pairs themselves, as face ids (smaller first).
std::vector<std::pair<int, int>> self_intersecting_pairs(const Mesh& mesh);
// Pairs among the faces whose bounding box overlaps one of `boxes` ({min, max} corners, mm):
// a local count for large meshes (every pair involving a face inside the boxes is counted).
std::size_t count_self_intersections_in(const Mesh& mesh, const std::vector<std::array<Vec3, 2>>& boxes);
}
