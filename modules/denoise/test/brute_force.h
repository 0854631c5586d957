#pragma once
// Reference answers for tests, independent of the module's homology annotations, source sets,
// bounded searches and lazy queue.
#include <vector>

#include "colonflat/core/mesh.h"

namespace cf::testing {

// True when cutting `mesh` along the closed edge loop disconnects the faces of its component
// (flood fill over faces that does not cross loop edges; bidirectional, so small disks are cheap).
bool loop_separates(const Mesh& mesh, const std::vector<Mesh::VertexHandle>& loop);

// Length of the shortest non-separating edge cycle avoiding boundary vertices, by exhaustion:
// from every vertex a full Dijkstra tree; every fundamental cycle through the root (a simple
// cycle); all of them sorted by length and tested with loop_separates() in that order. Only
// cycles of length <= upper_bound are considered (returns +inf when none is non-separating).
double brute_force_shortest_nonseparating(const Mesh& mesh, double upper_bound,
                                          std::vector<Mesh::VertexHandle>* loop = nullptr);

}  // namespace cf::testing
