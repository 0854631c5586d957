// Vertex adjacency of a triangle list (vertex_graph.h), from the corners grouped by vertex.
#include "colonflat/core/vertex_graph.h"

#include <algorithm>

#include "colonflat/core/threads.h"
#include "colonflat/core/vertex_corners.h"

namespace cf {
namespace {

// The other two corners of each of v's triangles, sorted: a neighbour listed once is joined to v
// by an edge that only one triangle has (a boundary edge), twice or more by an inner edge.
void gather_ends(const TriangleList& s, const VertexCorners& vc, std::size_t v, std::vector<int>& ends) {
  ends.clear();
  for (const std::uint32_t* c = vc.begin(v); c != vc.begin(v) + vc.degree(v); ++c) {
    const auto& t = s.triangles[*c / 3];
    const unsigned k = *c % 3;
    ends.push_back(t[(k + 1) % 3]);
    ends.push_back(t[(k + 2) % 3]);
  }
  std::sort(ends.begin(), ends.end());
}

// Writes v's distinct neighbours (ascending) at `out` and returns how many; flags v when one of
// its edges is a boundary edge (the far end is flagged by its own row: the edge is in both).
int row_of(const std::vector<int>& ends, int* out, char& boundary) {
  int n = 0;
  for (std::size_t k = 0; k < ends.size();) {
    std::size_t e = k;
    while (e < ends.size() && ends[e] == ends[k]) ++e;
    if (e - k == 1) boundary = 1;
    out[n] = ends[k];
    ++n;
    k = e;
  }
  return n;
}

}  // namespace

VertexGraph vertex_graph(const TriangleList& surface) {
  const std::size_t n = surface.points.size();
  const VertexCorners vc = vertex_corners(surface.triangles, n);
  VertexGraph g;
  g.on_boundary.assign(n, 0);
  g.start.assign(n + 1, 0);
  // One pass over fixed chunks of vertices (identical for any thread count): each row written at
  // its room in `rows` (2 per corner, an upper bound of its length), then the rows packed.
  std::vector<int> rows(2 * vc.corner.size());
  parallel_for(n, [&](std::size_t b, std::size_t e) {
    std::vector<int> ends;
    for (std::size_t v = b; v < e; ++v) {
      gather_ends(surface, vc, v, ends);
      g.start[v + 1] = row_of(ends, rows.data() + 2 * std::size_t(vc.start[v]), g.on_boundary[v]);
    }
  });
  for (std::size_t i = 0; i < n; ++i) g.start[i + 1] += g.start[i];
  g.neighbours.resize(std::size_t(g.start[n]));
  parallel_for(n, [&](std::size_t b, std::size_t e) {
    for (std::size_t v = b; v < e; ++v)
      std::copy_n(rows.data() + 2 * std::size_t(vc.start[v]), g.start[v + 1] - g.start[v], g.neighbours.data() + g.start[v]);
  });
  return g;
}

}  // namespace cf
