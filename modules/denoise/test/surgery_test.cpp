// Topological surgery: cutting a non-separating loop lowers the genus by one, keeps the surface
// closed, manifold, consistently oriented and connected; the two caps are apart.
#include <gtest/gtest.h>

#include <algorithm>

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

// vertices_connected keeps per-thread marks between calls: on two disjoint tori (128 vertices
// each) it answers false across them and true within each, call after call and after calls on a
// larger mesh (no mark of an earlier call counts).
TEST(DenoiseSurgery, VerticesConnectedAcrossCallsAndMeshes) {
  const Mesh big = to_mesh(torus(3, 1, 64, 32));
  const Mesh two = to_mesh(disjoint_union(torus(3, 1, 16, 8), torus(3, 1, 16, 8)));
  ASSERT_EQ(two.n_vertices(), 256u);
  for (int round = 0; round < 20; ++round) {
    EXPECT_TRUE(vertices_connected(big, VH(0), VH(static_cast<int>(big.n_vertices()) - 1)));
    EXPECT_FALSE(vertices_connected(two, VH(0), VH(128)));
    EXPECT_TRUE(vertices_connected(two, VH(0), VH(127)));
    EXPECT_TRUE(vertices_connected(two, VH(130), VH(255)));
    EXPECT_FALSE(vertices_connected(two, VH(255), VH(5)));
  }
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

namespace cf {
namespace {

// undo_surgery() gives back the mesh before the cut: same elements, same faces (corner ids),
// same positions, genus 1 again; a second cut of another loop then works as on a fresh mesh.
TEST(DenoiseSurgery, UndoRestoresTheMesh) {
  const int nu = 16, nv = 8;
  const Mesh original = synthetic::to_mesh(synthetic::torus(3, 1, nu, nv));
  Mesh m = original;
  FaceGrid grid(m, 0.5);
  SurgeryOptions so;
  so.guard = &grid;
  const SurgeryResult r = cut_and_cap(m, meridian(5, nv), so);
  ASSERT_EQ(analyze_topology(m).genus, 0);
  undo_surgery(m, r.undo);
  ASSERT_EQ(m.n_vertices(), original.n_vertices());
  ASSERT_EQ(m.n_edges(), original.n_edges());
  ASSERT_EQ(m.n_faces(), original.n_faces());
  for (auto f : original.faces()) {
    std::vector<int> a, b;
    for (auto v : original.fv_range(f)) a.push_back(v.idx());
    for (auto v : m.fv_range(Mesh::FaceHandle(f.idx()))) b.push_back(v.idx());
    EXPECT_EQ(a, b) << "face " << f.idx();
  }
  for (auto v : original.vertices()) EXPECT_EQ(original.point(v), m.point(Mesh::VertexHandle(v.idx())));
  const auto t = analyze_topology(m);
  EXPECT_EQ(t.genus, 1);
  EXPECT_TRUE(t.closed && t.manifold && t.consistently_oriented);
  cut_and_cap(m, meridian(11, nv), SurgeryOptions{});
  EXPECT_EQ(analyze_topology(m).genus, 0);
  EXPECT_TRUE(analyze_topology(m).manifold);
}

}  // namespace
}  // namespace cf
