#pragma once
// The corners of a triangle list grouped by vertex (compressed rows), built by one counting sort:
// no comparison sort and no per-edge records. What a per-vertex pass needs to find the edges and
// fans around each vertex (core analyze_topology); a module that numbers edges in (min, max)
// order can gather, for each vertex lo, the half-edges of its corners whose other end is >= lo.
#include <array>
#include <cstdint>
#include <vector>

namespace cf {

struct VertexCorners {
  // Corners of vertex v: corner[start[v]] .. corner[start[v + 1] - 1], each 3 f + k (corner k
  // of triangle f), in increasing f and k. Shapes: start #P + 1, corner 3 #T.
  std::vector<std::uint32_t> start, corner;

  std::uint32_t degree(std::size_t v) const { return start[v + 1] - start[v]; }
  const std::uint32_t* begin(std::size_t v) const { return corner.data() + start[v]; }
};

// Preconditions: every id in [0, n_vertices); 3 #T < 2^32.
VertexCorners vertex_corners(const std::vector<std::array<int, 3>>& triangles, std::size_t n_vertices);

}  // namespace cf
