// vertex_graph (core/vertex_graph.h): neighbours and boundary vertices against brute force.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "colonflat/core/threads.h"
#include "colonflat/core/vertex_graph.h"

namespace cf {
namespace {

// An n x n grid, two triangles per cell, with the cells listed in `skip` left out (holes).
TriangleList grid(int n, const std::set<int>& skip = {}) {
  TriangleList t;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) t.points.push_back({double(x), double(y), 0.0});
  for (int y = 0; y + 1 < n; ++y)
    for (int x = 0; x + 1 < n; ++x) {
      if (skip.count(y * n + x)) continue;
      const int a = y * n + x;
      t.triangles.push_back({a, a + 1, a + n + 1});
      t.triangles.push_back({a, a + n + 1, a + n});
    }
  return t;
}

// Every row equals the brute-force neighbour set, and a vertex is on the boundary exactly when one
// of its edges has one triangle: on a 6 x 6 grid with a hole of 2 cells (its rim and the border).
TEST(VertexGraph, NeighboursAndBoundaryMatchBruteForce) {
  const TriangleList t = grid(6, {14, 15});
  const VertexGraph g = vertex_graph(t);
  ASSERT_EQ(g.start.size(), t.points.size() + 1);
  std::vector<std::set<int>> nbr(t.points.size());
  std::multiset<std::pair<int, int>> undirected;
  for (const auto& f : t.triangles)
    for (int k = 0; k < 3; ++k) {
      const int a = f[k], b = f[(k + 1) % 3];
      nbr[a].insert(b), nbr[b].insert(a);
      undirected.insert({std::min(a, b), std::max(a, b)});
    }
  std::vector<char> boundary(t.points.size(), 0);
  for (const auto& e : undirected)
    if (undirected.count(e) == 1) boundary[e.first] = boundary[e.second] = 1;
  std::size_t boundary_count = 0;
  for (std::size_t v = 0; v < t.points.size(); ++v) {
    const std::set<int> row(g.neighbours.begin() + g.start[v], g.neighbours.begin() + g.start[v + 1]);
    EXPECT_EQ(row, nbr[v]) << v;
    EXPECT_EQ(g.degree(v), nbr[v].size()) << v;
    EXPECT_EQ(g.on_boundary[v], boundary[v]) << v;
    boundary_count += boundary[v];
  }
  EXPECT_EQ(boundary_count, 20u + 6u);  // the border (20) and the rim of the 2 x 1-cell hole (6)
}

// A closed surface (tetrahedron) has no boundary; an unused point has no neighbours.
TEST(VertexGraph, ClosedSurfaceAndIsolatedPoint) {
  TriangleList t;
  t.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {5, 5, 5}};
  t.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  const VertexGraph g = vertex_graph(t);
  for (std::size_t v = 0; v < 4; ++v) {
    EXPECT_EQ(g.degree(v), 3u);
    EXPECT_EQ(g.on_boundary[v], 0);
  }
  EXPECT_EQ(g.degree(4), 0u);
}

// Rows are ascending and the graph is the same, array for array, with 1 and 3 threads (a grid
// large enough to be split into several chunks, with holes).
TEST(VertexGraph, RowsAscendingAndSameForAnyThreadCount) {
  const TriangleList t = grid(40, {41, 42, 300, 777, 1200});
  set_thread_count(1);
  const VertexGraph one = vertex_graph(t);
  set_thread_count(3);
  const VertexGraph three = vertex_graph(t);
  set_thread_count(0);
  EXPECT_EQ(one.start, three.start);
  EXPECT_EQ(one.neighbours, three.neighbours);
  EXPECT_EQ(one.on_boundary, three.on_boundary);
  for (std::size_t v = 0; v < t.points.size(); ++v)
    EXPECT_TRUE(std::is_sorted(one.neighbours.begin() + one.start[v], one.neighbours.begin() + one.start[v + 1])) << v;
}

}  // namespace
}  // namespace cf
