#pragma once
// The vertex adjacency of a triangle list in compressed rows, for per-vertex loops over neighbours
// (smoothing, fairing, region growing) without a halfedge mesh.
#include <cstddef>
#include <vector>

#include "colonflat/core/soup.h"

namespace cf {

struct VertexGraph {
  std::vector<int> start;         // #P + 1 offsets into `neighbours`
  std::vector<int> neighbours;    // the neighbours of vertex v: [start[v], start[v + 1]), ascending
  std::vector<char> on_boundary;  // #P: 1 for the ends of an edge that only one triangle has
  std::size_t degree(std::size_t v) const { return std::size_t(start[v + 1] - start[v]); }
};

// surface: #P points, #T triangles with ids in [0, #P). Each undirected edge appears in the rows of
// both its ends, once. Isolated points have no neighbours. O(T) (one counting sort of the corners,
// each vertex's short row sorted), split over cf::thread_count() threads; the same for any count.
VertexGraph vertex_graph(const TriangleList& surface);

}  // namespace cf
