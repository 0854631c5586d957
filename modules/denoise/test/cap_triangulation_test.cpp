// Minimum-area triangulation of closed polygons: proper on planar polygons, in ear order (the
// order surgery adds cap faces), and restricted to the triangles `allowed` accepts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include "colonflat/denoise/cap_triangulation.h"

namespace cf {
namespace {

double triangulation_area(const std::vector<Vec3>& ring, const std::vector<std::array<int, 3>>& tris) {
  double a = 0;
  for (const auto& t : tris) a += 0.5 * OpenMesh::cross(ring[t[1]] - ring[t[0]], ring[t[2]] - ring[t[0]]).norm();
  return a;
}

// True when each triangle, in order, is three consecutive corners of the polygon left by
// clipping the ones before it (the order in which surgery adds cap faces).
bool ear_order(int n, const std::vector<std::array<int, 3>>& tris) {
  std::vector<int> poly(n);
  for (int i = 0; i < n; ++i) poly[i] = i;
  for (const auto& t : tris) {
    bool clipped = false;
    for (std::size_t j = 0; j < poly.size() && !clipped; ++j) {
      const std::size_t j1 = (j + 1) % poly.size(), j2 = (j + 2) % poly.size();
      if (poly[j] == t[0] && poly[j1] == t[1] && poly[j2] == t[2]) {
        poly.erase(poly.begin() + static_cast<long>(j1));
        clipped = true;
      }
    }
    if (!clipped) return false;
  }
  return poly.size() == 2;
}

// A planar non-convex polygon (an L) gets a proper triangulation: n - 2 triangles in ear order,
// all turning the polygon's way, covering exactly its area (4 unit squares).
TEST(DenoiseCapTriangulation, MinAreaTriangulationOfPlanarPolygon) {
  const std::vector<Vec3> L = {Vec3(0, 0, 0), Vec3(3, 0, 0), Vec3(3, 1, 0), Vec3(1, 1, 0), Vec3(1, 2, 0), Vec3(0, 2, 0)};
  const auto tris = min_area_triangulation(L);
  ASSERT_EQ(tris.size(), L.size() - 2);
  EXPECT_TRUE(ear_order(static_cast<int>(L.size()), tris));
  EXPECT_NEAR(triangulation_area(L, tris), 4.0, 1e-12);
  for (const auto& t : tris) EXPECT_GT(OpenMesh::cross(L[t[1]] - L[t[0]], L[t[2]] - L[t[0]])[2], 0);
}

// On a long, bumpy 3D ring (300 corners) the triangulation still comes in ear order.
TEST(DenoiseCapTriangulation, MinAreaTriangulationIsInEarOrder) {
  std::vector<Vec3> ring;
  for (int i = 0; i < 300; ++i) {
    const double a = 2 * M_PI * i / 300;
    ring.push_back(Vec3(3 * std::cos(a), std::sin(a), 0.3 * std::sin(7 * a)));
  }
  const auto tris = min_area_triangulation(ring);
  ASSERT_EQ(tris.size(), ring.size() - 2);
  EXPECT_TRUE(ear_order(static_cast<int>(ring.size()), tris));
}

// `allowed` is obeyed: forbidding every diagonal at vertex 0 forces the ear (0, 1, 5); forbidding
// everything yields no triangulation.
TEST(DenoiseCapTriangulation, MinAreaTriangulationRespectsAllowed) {
  std::vector<Vec3> hexagon;
  for (int i = 0; i < 6; ++i) hexagon.push_back(Vec3(std::cos(i * M_PI / 3), std::sin(i * M_PI / 3), 0));
  auto no_diagonal_at_0 = [](int i, int m, int j) { return i != 0 || (m == 1 && j == 5); };
  const auto tris = min_area_triangulation(hexagon, no_diagonal_at_0);
  ASSERT_EQ(tris.size(), 4u);
  for (const auto& t : tris) EXPECT_TRUE(no_diagonal_at_0(t[0], t[1], t[2]));
  EXPECT_NE(std::find(tris.begin(), tris.end(), std::array<int, 3>{0, 1, 5}), tris.end());
  EXPECT_NEAR(triangulation_area(hexagon, tris), 1.5 * std::sqrt(3.0), 1e-12);
  EXPECT_TRUE(min_area_triangulation(hexagon, [](int, int, int) { return false; }).empty());
}

// A bumpy 3D ring of n corners (the shape of a cut loop on a wrinkled wall).
std::vector<Vec3> bumpy_ring(int n) {
  std::vector<Vec3> ring;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    ring.push_back(Vec3(3 * std::cos(a), std::sin(a), 0.4 * std::sin(5 * a) + 0.1 * std::cos(11 * a)));
  }
  return ring;
}

// The old programme, written out as the reference: every subproblem's candidates sorted by
// (weight, apex) and `allowed` asked lightest first until one passes; with `side_ok`, each
// subproblem's side (i, j) but the ring edge is asked first and a refused side leaves it without a
// triangle. Per subproblem (i, j): its apex (arg[i n + j], -1: none).
std::vector<int> lightest_first_apexes(const std::vector<Vec3>& p, const std::function<bool(int, int, int)>& allowed,
                                       const std::function<bool(int, int)>& side_ok = {}) {
  const int n = static_cast<int>(p.size());
  const double none = std::numeric_limits<double>::infinity();
  std::vector<double> W(std::size_t(n) * n, 0.0);
  std::vector<int> arg(std::size_t(n) * n, -1);
  for (int len = 2; len < n; ++len)
    for (int i = 0; i + len < n; ++i) {
      const int j = i + len;
      std::vector<std::pair<double, int>> order;
      for (int m = i + 1; m < j; ++m) {
        const double w = W[std::size_t(i) * n + m] + W[std::size_t(m) * n + j] +
                         0.5 * OpenMesh::cross(p[m] - p[i], p[j] - p[i]).norm();
        if (w < none) order.push_back({w, m});
      }
      std::sort(order.begin(), order.end());
      W[std::size_t(i) * n + j] = none;
      const bool edge = i == 0 && j == n - 1;
      if (side_ok && (order.empty() || (!edge && !side_ok(i, j)))) continue;
      for (const auto& [w, m] : order)
        if (allowed(i, m, j)) {
          W[std::size_t(i) * n + j] = w, arg[std::size_t(i) * n + j] = m;
          break;
        }
    }
  return arg;
}

// The reference's triangles (empty when the whole ring has none).
std::vector<std::array<int, 3>> lightest_first_reference(const std::vector<Vec3>& p,
                                                         const std::function<bool(int, int, int)>& allowed) {
  const int n = static_cast<int>(p.size());
  const std::vector<int> arg = lightest_first_apexes(p, allowed);
  std::vector<std::array<int, 3>> tris;
  std::vector<std::pair<int, int>> stack{{0, n - 1}};
  while (!stack.empty()) {
    const auto [i, j] = stack.back();
    stack.pop_back();
    if (j - i < 2) continue;
    const int m = arg[std::size_t(i) * n + j];
    if (m < 0) return {};
    tris.push_back({i, m, j});
    stack.push_back({i, m});
    stack.push_back({m, j});
  }
  std::reverse(tris.begin(), tris.end());
  return tris;
}

// A pure pseudo-random refusal of about `percent` % of the triangles (or sides: j = -1).
bool refused(int i, int m, int j, int percent) {
  const unsigned h = static_cast<unsigned>(i * 73856093 ^ m * 19349663 ^ (j + 7) * 83492791);
  return (h >> 7) % 100 < static_cast<unsigned>(percent);
}

// Without refusals the lazy programme asks `allowed` only for the n - 2 triangles of its solution
// (the lightest-first one asked once per subproblem, about n^2 / 2 times): 58 asks on a 60-vertex
// ring, and the same triangles as the reference.
TEST(DenoiseCapTriangulation, LazyProgrammeAsksOnlyTheSolutionsTriangles) {
  const std::vector<Vec3> ring = bumpy_ring(60);
  int asked = 0;
  auto yes = [&](int, int, int) { return ++asked, true; };
  const auto tris = min_area_triangulation(ring, yes);
  EXPECT_EQ(asked, 58);
  EXPECT_EQ(tris, lightest_first_reference(ring, [](int, int, int) { return true; }));
}

// Refusals of a quarter of the triangles (lazy rounds), or of a fifth of the sides and a tenth of
// the triangles (lightest first, with side_ok): the same triangles, in the same order, as the
// reference, which asks every subproblem's candidates lightest first.
TEST(DenoiseCapTriangulation, RestrictedProgrammesGiveTheLightestAllowedTriangulation) {
  const std::vector<Vec3> ring = bumpy_ring(48);
  const int n = static_cast<int>(ring.size());
  auto quarter = [](int i, int m, int j) { return !refused(i, m, j, 25); };
  const auto lazy = min_area_triangulation(ring, quarter);
  ASSERT_EQ(lazy.size(), ring.size() - 2);
  EXPECT_EQ(lazy, lightest_first_reference(ring, quarter));
  auto side_ok = [](int a, int b) { return !refused(a, b, -1, 20); };
  auto tenth = [](int i, int m, int j) { return !refused(i, m, j, 10); };
  auto both = [&](int i, int m, int j) {
    auto ok = [&](int a, int b) { return b - a == 1 || (a == 0 && b == n - 1) || side_ok(a, b); };
    return ok(i, m) && ok(m, j) && ok(i, j) && tenth(i, m, j);
  };
  const auto eager = min_area_triangulation(ring, tenth, {}, side_ok);
  ASSERT_EQ(eager.size(), ring.size() - 2);
  EXPECT_EQ(eager, lightest_first_reference(ring, both));
  EXPECT_EQ(min_area_triangulation(ring, both), eager);  // the lazy rounds, sides asked with the triangle
}

// A planar ring of 40 vertices (radius 10) with a wall (two triangles, 6 x 10) standing across
// its centre: every triangulation of the ring covers the centre and crosses the wall.
Mesh pierced_ring(std::vector<Mesh::VertexHandle>* ring) {
  Mesh m;
  for (int i = 0; i < 40; ++i) {  // no ring vertex in the wall's plane y = 0
    const double t = (i + 0.5) * M_PI / 20;
    ring->push_back(m.add_vertex(Vec3(10 * std::cos(t), 10 * std::sin(t), 0)));
  }
  const auto a = m.add_vertex(Vec3(-3, 0, -5)), b = m.add_vertex(Vec3(3, 0, -5)), c = m.add_vertex(Vec3(3, 0, 5)),
             d = m.add_vertex(Vec3(-3, 0, 5));
  m.add_face(a, b, c);
  m.add_face(a, c, d);
  return m;
}

// The restricted triangulation stops once its grid queries exceed the budget (surgery's fail-fast,
// issue 26): on a ring no clean triangulation exists for, the unbounded search finds none after
// thousands of queries; with a budget of 100 it also returns none, after at most one more
// subproblem length (at most 40 x 40 queries), and the budget comes back spent.
TEST(DenoiseCapTriangulation, RestrictedTriangulationStopsAtItsBudget) {
  std::vector<Mesh::VertexHandle> ring;
  const Mesh m = pierced_ring(&ring);
  const FaceGrid grid(m, 1.0);
  auto never = [](Mesh::VertexHandle, Mesh::VertexHandle) { return false; };
  long long unbounded = 1LL << 60;
  EXPECT_TRUE(triangulate_ring(m, ring, never, &grid, {}, &unbounded).empty());
  const long long spent_unbounded = (1LL << 60) - unbounded;
  long long budget = 100;
  EXPECT_TRUE(triangulate_ring(m, ring, never, &grid, {}, &budget).empty());
  const long long spent = 100 - budget;
  EXPECT_GT(spent, 100);
  EXPECT_LE(spent, 100 + 40 * 40);
  EXPECT_GT(spent_unbounded, 2 * spent);
  // Without the wall the same ring triangulates within the budget's scale: the refusal is the wall's.
  Mesh free_ring;
  std::vector<Mesh::VertexHandle> ring2;
  for (const auto v : ring) ring2.push_back(free_ring.add_vertex(m.point(v)));
  const auto f = free_ring.add_vertex(Vec3(50, 50, 50));
  free_ring.add_face(f, free_ring.add_vertex(Vec3(51, 50, 50)), free_ring.add_vertex(Vec3(50, 51, 50)));
  const FaceGrid far_grid(free_ring, 1.0);
  long long enough = 100000;
  EXPECT_EQ(triangulate_ring(free_ring, ring2, never, &far_grid, {}, &enough).size(), 38u);
}

// A shared RingQueryCache gives the same triangulations and spends the same budget as fresh
// queries, in either order of a call that avoids `others` (a triangle piercing the ring's plane
// near its centre) and one that avoids the grid only: refusals caused by `others` are not
// reused as the grid's, and triangles clean of the grid are not accepted where `others` refuse them.
TEST(DenoiseCapTriangulation, QueryCacheGivesTheSameTriangulations) {
  constexpr double kPi = 3.14159265358979323846;
  Mesh m;
  std::vector<Mesh::VertexHandle> ring;
  for (int i = 0; i < 12; ++i) ring.push_back(m.add_vertex(Vec3(std::cos(2 * kPi * i / 12), std::sin(2 * kPi * i / 12), 0)));
  const auto f = m.add_vertex(Vec3(50, 50, 50));  // the grid's one face, far away
  m.add_face(f, m.add_vertex(Vec3(51, 50, 50)), m.add_vertex(Vec3(50, 51, 50)));
  const std::vector<std::array<int, 3>> blocker = {
      {m.add_vertex(Vec3(0.2, 0, -1)).idx(), m.add_vertex(Vec3(0.25, 0, 1)).idx(), m.add_vertex(Vec3(0.15, 0, 1)).idx()}};
  const FaceGrid grid(m, 1.0);
  auto never = [](Mesh::VertexHandle, Mesh::VertexHandle) { return false; };
  auto run = [&](const std::vector<std::array<int, 3>>& others, RingQueryCache* cache, long long* spent) {
    long long budget = 1000000;
    auto t = triangulate_ring(m, ring, never, &grid, others, &budget, cache);
    *spent = 1000000 - budget;
    return t;
  };
  long long spent_free = 0, spent_blocked = 0, spent = 0;
  const auto free_cap = run({}, nullptr, &spent_free), blocked_cap = run(blocker, nullptr, &spent_blocked);
  ASSERT_EQ(free_cap.size(), 10u);
  ASSERT_EQ(blocked_cap.size(), 10u);
  ASSERT_NE(free_cap, blocked_cap);  // the blocker refuses the free cap's triangles
  RingQueryCache blocked_first, free_first;
  EXPECT_EQ(run(blocker, &blocked_first, &spent), blocked_cap);
  EXPECT_EQ(spent, spent_blocked);
  EXPECT_EQ(run({}, &blocked_first, &spent), free_cap);
  EXPECT_EQ(spent, spent_free);
  EXPECT_EQ(run({}, &free_first, &spent), free_cap);
  EXPECT_EQ(run(blocker, &free_first, &spent), blocked_cap);
  EXPECT_EQ(spent, spent_blocked);
}

// Lightest first with side_ok (the restricted caps' programme, which now forms a subproblem's
// other candidates only once its lightest is refused): the same questions, sides and triangles in
// the same order, and the same triangles as the old programme (written out here: per subproblem,
// the side unless a ring edge, then every candidate sorted by (weight, apex) until one passes),
// with a fifth of the sides and a third of the triangles refused.
TEST(DenoiseCapTriangulation, LightestFirstAsksWhatTheOldProgrammeAsked) {
  const std::vector<Vec3> ring = bumpy_ring(40);
  const int n = static_cast<int>(ring.size());
  std::vector<std::array<int, 3>> asked, expected;
  auto third = [&](int i, int m, int j) { return asked.push_back({i, m, j}), !refused(i, m, j, 33); };
  auto side_ok = [&](int a, int b) { return asked.push_back({a, b, -1}), !refused(a, b, -1, 20); };
  const auto tris = min_area_triangulation(ring, third, {}, side_ok);
  const std::vector<int> arg = lightest_first_apexes(
      ring, [&](int i, int m, int j) { return expected.push_back({i, m, j}), !refused(i, m, j, 33); },
      [&](int i, int j) { return expected.push_back({i, j, -1}), !refused(i, j, -1, 20); });
  EXPECT_EQ(asked, expected);
  ASSERT_EQ(tris.size(), ring.size() - 2);
  for (const auto& t : tris) EXPECT_EQ(arg[std::size_t(t[0]) * n + t[2]], t[1]);
}

}  // namespace
}  // namespace cf
