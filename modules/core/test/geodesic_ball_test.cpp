// vertices_within (geodesic_ball.cpp): graph-distance balls on generated flat grids, checked
// against the analytic distances and against a plain hash-map Dijkstra, including calls that
// reuse the per-thread labels of a larger mesh.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <queue>
#include <unordered_map>
#include <utility>

#include "colonflat/core/geodesic_ball.h"

namespace cf {
namespace {

// A flat n x n vertex grid of spacing h, every square split along its (i, j) -> (i+1, j+1)
// diagonal; vertex (i, j) has id i * n + j.
Mesh grid(int n, double h) {
  Mesh m;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) m.add_vertex(Vec3(i * h, j * h, 0));
  auto v = [&](int i, int j) { return Mesh::VertexHandle(i * n + j); };
  for (int i = 0; i + 1 < n; ++i)
    for (int j = 0; j + 1 < n; ++j) {
      m.add_face(v(i, j), v(i + 1, j), v(i + 1, j + 1));
      m.add_face(v(i, j), v(i + 1, j + 1), v(i, j + 1));
    }
  return m;
}

// The multi-source Dijkstra with its labels in a hash map (the reference: same queue order).
std::vector<int> reference_ball(const Mesh& mesh, const std::vector<Mesh::VertexHandle>& seeds, double radius,
                                std::vector<double>* distances) {
  std::unordered_map<int, double> dist;
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  for (auto s : seeds) dist[s.idx()] = 0, queue.push({0, s.idx()});
  std::vector<int> out;
  while (!queue.empty()) {
    const auto [d, v] = queue.top();
    queue.pop();
    if (d > dist[v]) continue;
    out.push_back(v);
    distances->push_back(d);
    for (auto w : mesh.vv_range(Mesh::VertexHandle(v))) {
      const double nd = d + (mesh.point(w) - mesh.point(Mesh::VertexHandle(v))).norm();
      if (nd > radius) continue;
      auto it = dist.find(w.idx());
      if (it == dist.end() || nd < it->second) dist[w.idx()] = nd, queue.push({nd, w.idx()});
    }
  }
  return out;
}

// From a corner of the grid, vertex (a, b) lies at b diagonals plus a - b axis steps (a >= b):
// h (|a - b| + sqrt2 min(a, b)); the ball holds exactly the vertices within the radius, nearest
// first.
TEST(GeodesicBall, CornerDistancesOnAGridAreAnalytic) {
  const int n = 12;
  const double h = 0.5, radius = 3.1;
  const Mesh m = grid(n, h);
  std::vector<double> d;
  const std::vector<int> ball = vertices_within(m, {Mesh::VertexHandle(0)}, radius, &d);
  ASSERT_EQ(ball.size(), d.size());
  std::size_t inside = 0;
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) inside += h * (std::abs(a - b) + std::sqrt(2.0) * std::min(a, b)) <= radius + 1e-12;
  EXPECT_EQ(ball.size(), inside);
  for (std::size_t k = 0; k < ball.size(); ++k) {
    const int a = ball[k] / n, b = ball[k] % n;
    EXPECT_NEAR(d[k], h * (std::abs(a - b) + std::sqrt(2.0) * std::min(a, b)), 1e-12) << a << ", " << b;
    if (k > 0) EXPECT_LE(d[k - 1], d[k]);
  }
}

// The same vertices, order and distances as the hash-map Dijkstra, for several seeds (one given
// twice) and radii, on a small grid right after balls on a larger one (whose labels the thread
// keeps) and on the larger one again.
TEST(GeodesicBall, SameBallsAsAHashMapDijkstraAcrossMeshes) {
  const Mesh big = grid(40, 0.3), small = grid(9, 1.0);
  for (int round = 0; round < 3; ++round)
    for (const Mesh* m : {&big, &small, &big}) {
      const int n = static_cast<int>(m->n_vertices());
      const std::vector<Mesh::VertexHandle> seeds = {Mesh::VertexHandle(n / 3), Mesh::VertexHandle(n - 1),
                                                     Mesh::VertexHandle(n / 3)};
      for (double radius : {0.0, 0.9, 2.5, 1e9}) {
        std::vector<double> got_d, want_d;
        const std::vector<int> got = vertices_within(*m, seeds, radius, &got_d);
        const std::vector<int> want = reference_ball(*m, seeds, radius, &want_d);
        EXPECT_EQ(got, want) << n << " vertices, radius " << radius;
        EXPECT_EQ(got_d, want_d);
      }
    }
}

// vertices_within_until is the ball cut short right after its last target: the same vertices,
// order and distances as vertices_within up to that target, strictly fewer than the whole ball
// when the targets are near the seed (a grid corner's ball of radius 1e9 is the whole grid),
// the whole ball when a target lies outside the radius, and nothing without targets.
TEST(GeodesicBall, UntilStopsRightAfterTheLastTarget) {
  const int n = 30;
  const Mesh m = grid(n, 0.5);
  const std::vector<Mesh::VertexHandle> seeds = {Mesh::VertexHandle(0)};
  std::vector<double> full_d;
  const std::vector<int> full = vertices_within(m, seeds, 1e9, &full_d);
  ASSERT_EQ(full.size(), m.n_vertices());
  const std::vector<int> targets = {3 * n + 2, 1, 3 * n + 2, 5};  // (3, 2), (0, 1), again, (0, 5)
  std::vector<double> got_d;
  const std::vector<int> got = vertices_within_until(m, seeds, 1e9, targets, &got_d);
  std::size_t last = 0;
  for (int t : targets) last = std::max<std::size_t>(last, std::find(full.begin(), full.end(), t) - full.begin());
  ASSERT_EQ(got.size(), last + 1);
  EXPECT_LT(got.size(), full.size() / 10);
  EXPECT_TRUE(std::equal(got.begin(), got.end(), full.begin()));
  EXPECT_TRUE(std::equal(got_d.begin(), got_d.end(), full_d.begin()));
  // (29, 29) lies 14.5 sqrt2 = 20.5 from the corner: outside a radius of 3, so the whole ball.
  std::vector<double> ball_d, until_d;
  const std::vector<int> ball = vertices_within(m, seeds, 3.0, &ball_d);
  EXPECT_EQ(vertices_within_until(m, seeds, 3.0, {5, n * n - 1}, &until_d), ball);
  EXPECT_EQ(until_d, ball_d);
  EXPECT_TRUE(vertices_within_until(m, seeds, 3.0, {}).empty());
}

}  // namespace
}  // namespace cf
