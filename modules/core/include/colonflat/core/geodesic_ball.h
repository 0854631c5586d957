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

// The first vertices of vertices_within(mesh, seeds, radius, distances), in its order and with its
// distances, up to and including the one that settles the last of `targets` (vertex ids; repeats
// allowed); all of them when some target is not within the radius. Every target within the radius
// is in the result with its exact distance; the search costs only the vertices nearer than the
// farthest target (issue 26: the far-first order of the denoise loop search, which needs the
// distances of a few sources, not the whole ball). Empty when `targets` is.
std::vector<int> vertices_within_until(const Mesh& mesh, const std::vector<Mesh::VertexHandle>& seeds, double radius,
                                       const std::vector<int>& targets, std::vector<double>* distances = nullptr);

}  // namespace cf
