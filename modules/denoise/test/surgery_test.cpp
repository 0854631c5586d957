// Topological surgery: cutting a non-separating loop lowers the genus by one, keeps the surface
// closed, manifold, consistently oriented and connected; the two caps are apart.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "colonflat/core/error.h"
#include "colonflat/core/synthetic.h"
#include "colonflat/core/topology.h"
#include "colonflat/denoise/surgery.h"

namespace cf {
namespace {

using namespace synthetic;
using VH = Mesh::VertexHandle;

std::vector<VH> meridian(int i, int nv) {
  std::vector<VH> l;
  for (int j = 0; j < nv; ++j) l.push_back(VH(i * nv + j));
  return l;
}

// Cutting a torus along a meridian gives a sphere: genus 0, closed, manifold, oriented, connected.
TEST(DenoiseSurgery, TorusMeridianGivesSphere) {
  const int nu = 16, nv = 8;
  Mesh m = to_mesh(torus(3, 1, nu, nv));
  const auto V = m.n_vertices(), F = m.n_faces();
  SurgeryResult r = cut_and_cap(m, meridian(5, nv), SurgeryOptions{});
  auto t = analyze_topology(m);
  EXPECT_EQ(t.genus, 0);
  EXPECT_TRUE(t.closed);
  EXPECT_TRUE(t.manifold);
  EXPECT_TRUE(t.consistently_oriented);
  EXPECT_EQ(t.components.size(), 1u);
  // Left copies, and per cap (m concentric rings, m = min(cap_rings, k / 4)): (m - 1) k ring
  // vertices + a centre, 2 (m - 1) k strip triangles + a fan of k.
  const std::size_t k = nv, mr = std::max<std::size_t>(1, std::min<std::size_t>(SurgeryOptions{}.cap_rings, k / 4));
  EXPECT_EQ(m.n_vertices(), V + k + 2 * ((mr - 1) * k + 1));
  EXPECT_EQ(m.n_faces(), F + 2 * (2 * (mr - 1) * k + k));
  EXPECT_TRUE(vertices_connected(m, r.left_cap, r.right_cap));
  // The right copies keep their ids; the caps are apart (at least a tenth of an edge).
  EXPECT_EQ(r.right_ring.front(), VH(5 * nv));
  EXPECT_GT((m.point(r.left_cap) - m.point(r.right_cap)).norm(), 0.1 * 2 * 3.14159 * 3 / nu * 0.25);
}

// With ring_pull = 0 and one cap ring the caps are the paper's: two coinciding centroid fans.
TEST(DenoiseSurgery, ZeroPullGivesPaperCaps) {
  Mesh m = to_mesh(torus(3, 1, 16, 8));
  SurgeryOptions o;
  o.ring_pull = 0;
  o.cap_rings = 1;
  SurgeryResult r = cut_and_cap(m, meridian(2, 8), o);
  EXPECT_LT((m.point(r.left_cap) - m.point(r.right_cap)).norm(), 1e-12);
  EXPECT_EQ(analyze_topology(m).genus, 0);
}

// Cutting the separating neck of a double torus splits it: the sides are no longer connected.
TEST(DenoiseSurgery, SeparatingNeckSplitsTheMesh) {
  Mesh m = to_mesh(torus_chain(2, 3, 1, 16, 8, 10));
  std::vector<VH> neck = {VH(0), VH(8), VH(9), VH(1)};
  SurgeryResult r = cut_and_cap(m, neck, SurgeryOptions{});
  EXPECT_FALSE(vertices_connected(m, r.left_cap, r.right_cap));
  auto t = analyze_topology(m);
  EXPECT_EQ(t.components.size(), 2u);
  EXPECT_EQ(t.genus, 2);  // 1 + 1: the separating cut removed no handle
}

// Two surgeries in a row on a genus-3 chain leave genus 1 and one component.
TEST(DenoiseSurgery, RepeatedSurgery) {
  Mesh m = to_mesh(torus_chain(3, 3, 1, 16, 8, 10));
  cut_and_cap(m, meridian(4, 8), SurgeryOptions{});
  // A meridian of the second torus (its vertices follow the first torus's 16 x 8).
  std::vector<VH> second;
  for (int j = 0; j < 8; ++j) second.push_back(VH(16 * 8 + 4 * 8 + j));
  cut_and_cap(m, second, SurgeryOptions{});
  auto t = analyze_topology(m);
  EXPECT_EQ(t.genus, 1);
  EXPECT_EQ(t.components.size(), 1u);
  EXPECT_TRUE(t.consistently_oriented);
}

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
TEST(DenoiseSurgery, MinAreaTriangulationOfPlanarPolygon) {
  const std::vector<Vec3> L = {Vec3(0, 0, 0), Vec3(3, 0, 0), Vec3(3, 1, 0), Vec3(1, 1, 0), Vec3(1, 2, 0), Vec3(0, 2, 0)};
  const auto tris = min_area_triangulation(L);
  ASSERT_EQ(tris.size(), L.size() - 2);
  EXPECT_TRUE(ear_order(static_cast<int>(L.size()), tris));
  EXPECT_NEAR(triangulation_area(L, tris), 4.0, 1e-12);
  for (const auto& t : tris) EXPECT_GT(OpenMesh::cross(L[t[1]] - L[t[0]], L[t[2]] - L[t[0]])[2], 0);
}

// On a long, bumpy 3D ring (300 corners) the triangulation still comes in ear order.
TEST(DenoiseSurgery, MinAreaTriangulationIsInEarOrder) {
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
TEST(DenoiseSurgery, MinAreaTriangulationRespectsAllowed) {
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

// FaceGrid::hits: a triangle piercing the surface is caught, one beside it is not, and so is a
// crossing with one of the extra triangles.
TEST(DenoiseSurgery, FaceGridHitsPiercingTriangles) {
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

// Invalid loops are refused with a reason: too short, not simple, not edge-connected, on the boundary.
TEST(DenoiseSurgery, PreconditionsAreChecked) {
  Mesh m = to_mesh(torus(3, 1, 16, 8));
  EXPECT_THROW(cut_and_cap(m, {VH(0), VH(1)}, SurgeryOptions{}), PreconditionError);
  EXPECT_THROW(cut_and_cap(m, {VH(0), VH(1), VH(2), VH(1)}, SurgeryOptions{}), PreconditionError);
  EXPECT_THROW(cut_and_cap(m, {VH(0), VH(2), VH(4)}, SurgeryOptions{}), PreconditionError);
  Mesh open = to_mesh(open_cylinder(1, 2, 8, 2));
  EXPECT_THROW(cut_and_cap(open, {VH(0), VH(1), VH(2), VH(3), VH(4), VH(5), VH(6), VH(7)}, SurgeryOptions{}),
               PreconditionError);
}

}  // namespace
}  // namespace cf
