// FaceGrid: intersections of new triangles with the surface and with each other.
#include <gtest/gtest.h>

#include <cmath>
#include <thread>

#include "colonflat/core/synthetic.h"
#include "colonflat/denoise/face_grid.h"

namespace cf {
namespace {

using namespace synthetic;

// FaceGrid::hits: a triangle piercing the surface is caught, one beside it is not, and so is a
// crossing with one of the extra triangles.
TEST(DenoiseFaceGrid, HitsPiercingTriangles) {
  Mesh m = to_mesh(sphere(1, 16, 8));
  const FaceGrid grid(m, 0.3);
  const auto in = m.add_vertex(Vec3(0, 0, 0.5)), out = m.add_vertex(Vec3(0, 0, 1.5)), side = m.add_vertex(Vec3(0.1, 0, 1.5));
  const auto far1 = m.add_vertex(Vec3(0, 0, 2)), far2 = m.add_vertex(Vec3(0.1, 0, 2)), far3 = m.add_vertex(Vec3(0, 0.1, 2));
  EXPECT_TRUE(grid.hits(m, {in.idx(), out.idx(), side.idx()}));
  EXPECT_FALSE(grid.hits(m, {far1.idx(), far2.idx(), far3.idx()}));
  const auto c1 = m.add_vertex(Vec3(-0.05, 0.05, 1.75)), c2 = m.add_vertex(Vec3(0.15, 0.05, 1.75)),
             c3 = m.add_vertex(Vec3(0.05, -0.2, 1.75));
  EXPECT_TRUE(grid.hits(m, {far1.idx(), far2.idx(), out.idx()}, {{c1.idx(), c2.idx(), c3.idx()}}));
}

// The grid built at construction (compressed rows per cell): erased faces are no longer hit,
// faces inserted again are, and a query box with more cells than the grid (which scans every
// row instead of looking cells up) finds the same hits.
TEST(DenoiseFaceGrid, ErasedFacesAreMissedUntilInsertedAgain) {
  Mesh m = to_mesh(sphere(1, 16, 8));
  FaceGrid grid(m, 0.3);
  const auto in = m.add_vertex(Vec3(0, 0, 0.5)), out = m.add_vertex(Vec3(0, 0, 1.5)), side = m.add_vertex(Vec3(0.1, 0, 1.5));
  const std::array<int, 3> pierce{in.idx(), out.idx(), side.idx()};
  const auto w1 = m.add_vertex(Vec3(-30, -30, 0)), w2 = m.add_vertex(Vec3(30, -30, 0)), w3 = m.add_vertex(Vec3(0, 30, 0));
  const std::array<int, 3> wide{w1.idx(), w2.idx(), w3.idx()};  // its box spans far more cells than the grid holds
  ASSERT_TRUE(grid.hits(m, pierce));
  ASSERT_TRUE(grid.hits(m, wide));
  EXPECT_GT(grid.count_triangles(m, {wide}), 8u);  // cuts the sphere along its equator
  std::vector<Mesh::FaceHandle> faces(m.faces().begin(), m.faces().end());
  for (auto f : faces) grid.erase(m, f);
  EXPECT_FALSE(grid.hits(m, pierce));
  EXPECT_FALSE(grid.hits(m, wide));
  for (auto f : faces) grid.insert(m, f);
  EXPECT_TRUE(grid.hits(m, pierce));
  EXPECT_TRUE(grid.hits(m, wide));
}

// The grid built at construction (one pass over the faces, rows filled from its list) holds what a
// grid given no faces and then every face through insert() holds: the same intersection count for
// each of 200 triangles across the sphere, in cells of 0.1 to 0.5 (faces spanning 1 to many cells).
TEST(DenoiseFaceGrid, BuiltGridHoldsWhatInsertingEveryFaceHolds) {
  Mesh m = to_mesh(sphere(1, 24, 12));
  std::vector<std::array<int, 3>> tris;
  for (int i = 0; i < 200; ++i) {  // corners spread over [-1.2, 1.2]^3 by a fixed recurrence
    std::array<int, 3> t{};
    for (int k = 0; k < 3; ++k) {
      const int j = 3 * i + k;
      t[k] = m.add_vertex(Vec3(1.2 * std::sin(1.3 * j), 1.2 * std::cos(2.1 * j), 1.2 * std::sin(0.7 * j + 1))).idx();
    }
    tris.push_back(t);
  }
  for (double cell : {0.1, 0.25, 0.5}) {
    const FaceGrid built(m, cell);
    FaceGrid inserted(m, cell, {});
    for (auto f : m.faces()) inserted.insert(m, f);
    std::size_t hits = 0;
    for (const auto& t : tris) {
      const std::size_t a = built.count_triangles(m, {t}), b = inserted.count_triangles(m, {t});
      EXPECT_EQ(a, b) << cell;
      hits += a;
    }
    EXPECT_GT(hits, 50u) << cell;  // the triangles do cross the sphere
  }
}

// FaceGrid::segment_hits: a chord through the unit sphere's wall (from inside to outside, in
// any direction, across many cells) pierces it; one inside it, and a chord between two surface
// vertices that runs inside, do not; whenever a chord pierces, a triangle on it hits.
TEST(DenoiseFaceGrid, SegmentHitsPiercingChords) {
  Mesh m = to_mesh(sphere(1, 24, 12));
  const FaceGrid grid(m, 0.1);
  const auto in = m.add_vertex(Vec3(0.1, -0.2, 0.3)), in2 = m.add_vertex(Vec3(-0.3, 0.2, -0.1));
  const auto out = m.add_vertex(Vec3(1.7, 1.1, -0.9)), out2 = m.add_vertex(Vec3(-1.2, -1.5, 1.3));
  EXPECT_TRUE(grid.segment_hits(m, in.idx(), out.idx()));
  EXPECT_TRUE(grid.segment_hits(m, out2.idx(), in.idx()));
  EXPECT_TRUE(grid.segment_hits(m, out.idx(), out2.idx()));  // through the sphere: two walls
  EXPECT_TRUE(grid.hits(m, {in.idx(), out.idx(), in2.idx()}));
  EXPECT_FALSE(grid.segment_hits(m, in.idx(), in2.idx()));
  const auto north = Mesh::VertexHandle(0), far = Mesh::VertexHandle(static_cast<int>(m.n_vertices()) / 2 - 7);
  ASSERT_GT((m.point(north) - m.point(far)).norm(), 0.5);
  EXPECT_FALSE(grid.segment_hits(m, north.idx(), far.idx()));  // a chord of the sphere, inside it
}

// FaceGrid::free_distance: from the centre of the unit sphere the ray meets the wall at about 1
// in any direction; the limit holds when nothing is nearer; faces at the start vertex are skipped.
TEST(DenoiseFaceGrid, FreeDistanceIsTheDistanceToTheWall) {
  Mesh m = to_mesh(sphere(1, 48, 24));
  const FaceGrid grid(m, 0.2);
  for (const Vec3 d : {Vec3(1, 0, 0), Vec3(0, 0, -1), Vec3(0.6, -0.48, 0.64)})
    EXPECT_NEAR(grid.free_distance(m, Vec3(0, 0, 0), d, 5.0, -1), 1.0, 0.01);
  EXPECT_DOUBLE_EQ(grid.free_distance(m, Vec3(0, 0, 0), Vec3(1, 0, 0), 0.5, -1), 0.5);
  const auto v = Mesh::VertexHandle(5);
  const Vec3 inward = -m.point(v) / m.point(v).norm();
  EXPECT_NEAR(grid.free_distance(m, m.point(v), inward, 5.0, v.idx()), 2.0, 0.02);
}

// The grid's answers for triangles spanning many cells (its queries skip the columns of cells
// that lie beyond an edge of the triangle's projection) are the brute-force ones: for 300
// triangles across a sphere, free or with a corner on the sphere (the shared-vertex rule), in
// cells of 0.05 to 0.3, hits() and count_triangles() equal a test against every face.
TEST(DenoiseFaceGrid, WideTriangleHitsAreTheBruteForceHits) {
  Mesh m = to_mesh(sphere(1, 32, 16));
  const int surface_vertices = static_cast<int>(m.n_vertices());
  std::vector<std::array<int, 3>> tris;
  for (int i = 0; i < 300; ++i) {  // corners spread over [-1.3, 1.3]^3 by a fixed recurrence
    std::array<int, 3> t{};
    for (int k = 0; k < 3; ++k) {
      const int j = 3 * i + k;
      t[k] = m.add_vertex(Vec3(1.3 * std::sin(1.7 * j), 1.3 * std::cos(0.9 * j + 2), 1.3 * std::sin(2.3 * j))).idx();
    }
    if (i % 3 == 0) t[0] = (7 * i) % surface_vertices;  // a corner on the sphere
    tris.push_back(t);
  }
  auto brute = [&](const std::array<int, 3>& t) {
    std::array<Vec3, 3> p;
    for (int k = 0; k < 3; ++k) p[k] = m.point(Mesh::VertexHandle(t[k]));
    std::size_t n = 0;
    for (auto f : m.faces()) {
      std::array<int, 3> ids{};
      std::array<Vec3, 3> q;
      int k = 0;
      for (auto v : m.fv_range(f)) ids[k] = v.idx(), q[k++] = m.point(v);
      n += triangles_intersect_improperly(t, p, ids, q) ? 1 : 0;
    }
    return n;
  };
  for (double cell : {0.05, 0.12, 0.3}) {
    const FaceGrid grid(m, cell);
    std::size_t hits = 0;
    for (const auto& t : tris) {
      const std::size_t n = brute(t);
      EXPECT_EQ(grid.count_triangles(m, {t}), n) << cell;
      EXPECT_EQ(grid.hits(m, t), n > 0) << cell;
      hits += n > 0;
    }
    EXPECT_GT(hits, 100u) << cell;  // many cross the sphere
    EXPECT_LT(hits, 300u) << cell;  // and some do not
  }
}

// Each query tests a face once however many of its cells it walks (per-thread marks, cleared by
// the next query): on a sphere whose faces span up to dozens of cells of 0.04, the answers of 200
// segments and 200 rays asked one after the other equal a test of every face, and two threads
// asking the same queries at once (as the restricted caps do) get the same answers.
TEST(DenoiseFaceGrid, SegmentAndRayAnswersAreTheBruteForceOnesOnAnyThread) {
  Mesh m = to_mesh(sphere(1, 20, 10));
  std::vector<std::pair<int, int>> segments;
  for (int i = 0; i < 200; ++i) {  // ends spread over [-1.4, 1.4]^3 by a fixed recurrence
    const auto a = m.add_vertex(Vec3(1.4 * std::sin(1.1 * i), 1.4 * std::cos(0.7 * i + 1), 1.4 * std::sin(2.9 * i)));
    const auto b = m.add_vertex(Vec3(1.4 * std::cos(1.9 * i), 1.4 * std::sin(0.3 * i + 2), 1.4 * std::cos(1.3 * i)));
    segments.push_back({a.idx(), b.idx()});
  }
  auto face_points = [&](Mesh::FaceHandle f) {
    std::array<Vec3, 3> q;
    int k = 0;
    for (auto v : m.fv_range(f)) q[k++] = m.point(v);
    return q;
  };
  auto brute_pierces = [&](int a, int b) {  // a proper crossing of the segment with a face
    const Vec3 p = m.point(Mesh::VertexHandle(a)), d = m.point(Mesh::VertexHandle(b)) - p;
    for (auto f : m.faces()) {
      const auto q = face_points(f);
      const Vec3 n = OpenMesh::cross(q[1] - q[0], q[2] - q[0]);
      const double t = OpenMesh::dot(q[0] - p, n) / OpenMesh::dot(d, n);
      if (!(t > 1e-6 && t < 1 - 1e-6)) continue;
      const Vec3 x = p + t * d;
      bool inside = true;
      for (int e = 0; e < 3; ++e) inside = inside && OpenMesh::dot(OpenMesh::cross(q[(e + 1) % 3] - q[e], x - q[e]), n) > 0;
      if (inside) return true;
    }
    return false;
  };
  const FaceGrid grid(m, 0.04);
  auto answers = [&](std::vector<int>* out) {
    for (const auto& [a, b] : segments) {
      out->push_back(grid.segment_hits(m, a, b) ? 1 : 0);
      const Vec3 p = m.point(Mesh::VertexHandle(a)), d = m.point(Mesh::VertexHandle(b)) - p;
      out->push_back(static_cast<int>(std::lround(1e6 * grid.free_distance(m, p, d / d.norm(), 3.0, -1))));
    }
  };
  std::vector<int> one, two_a, two_b;
  answers(&one);
  std::thread helper([&] { answers(&two_b); });
  answers(&two_a);
  helper.join();
  EXPECT_EQ(one, two_a);
  EXPECT_EQ(one, two_b);
  int pierced = 0;
  for (std::size_t i = 0; i < segments.size(); ++i) {
    const bool brute = brute_pierces(segments[i].first, segments[i].second);
    EXPECT_EQ(one[2 * i] == 1, brute) << i;
    pierced += brute;
    const Vec3 p = m.point(Mesh::VertexHandle(segments[i].first));
    const Vec3 d = m.point(Mesh::VertexHandle(segments[i].second)) - p;
    double nearest = 3.0;  // the ray's first face, brute force (Moller-Trumbore as a plane + inside test)
    for (auto f : m.faces()) {
      const auto q = face_points(f);
      const Vec3 n = OpenMesh::cross(q[1] - q[0], q[2] - q[0]), u = d / d.norm();
      const double t = OpenMesh::dot(q[0] - p, n) / OpenMesh::dot(u, n);
      if (!(t > 1e-9 && t < nearest)) continue;
      const Vec3 x = p + t * u;
      bool inside = true;
      for (int e = 0; e < 3; ++e) inside = inside && OpenMesh::dot(OpenMesh::cross(q[(e + 1) % 3] - q[e], x - q[e]), n) >= 0;
      if (inside) nearest = t;
    }
    EXPECT_NEAR(one[2 * i + 1] * 1e-6, nearest, 2e-6) << i;
  }
  EXPECT_GT(pierced, 50);   // many segments cross the sphere
  EXPECT_LT(pierced, 200);  // and some do not
}

}  // namespace
}  // namespace cf
