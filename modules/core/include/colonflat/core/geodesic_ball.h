#pragma once
// Graph-distance balls on a triangle mesh (Euclidean edge lengths): the shared multi-source
// Dijkstra used by denoise (loop search bookkeeping, stump growth).
#include <vector>

#include "colonflat/core/mesh.h"

namespace cf {

// Vertices within graph distance `radius` (mm, >= 0) of any seed, nearest first (multi-source
// Dijkstra over mesh edges, Euclidean lengths). Seeds are included at distance 0. When
// `distances` is given it receives the distance of each returned vertex (same order).
// Cost: O(m log m) for the m vertices reached, so a small ball on a large mesh is cheap; the
// distance labels are per-thread arrays by vertex id kept between calls (12 bytes per vertex of
// the largest mesh seen), of which a call touches only the vertices it reaches.
std::vector<int> vertices_within(const Mesh& mesh, const std::vector<Mesh::VertexHandle>& seeds, double radius,
                                 std::vector<double>* distances = nullptr);

}  // namespace cf
