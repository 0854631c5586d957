// Topology conventions (docs/conventions.md) on programmatic meshes with known answers.
#include <gtest/gtest.h>

#include <cmath>

#include "colonflat/core/synthetic.h"
#include "colonflat/core/topology.h"

namespace cf {
namespace {

using namespace synthetic;

// A sphere is one closed component of genus 0 with chi = 2.
TEST(Topology, SphereIsGenusZero) {
  auto t = analyze_topology(sphere(1.0, 16, 8));
  EXPECT_EQ(t.euler, 2);
  ASSERT_TRUE(t.genus.has_value());
  EXPECT_EQ(*t.genus, 0);
  EXPECT_EQ(t.components.size(), 1u);
  EXPECT_TRUE(t.closed);
  EXPECT_TRUE(t.manifold);
  EXPECT_TRUE(t.orientable);
  EXPECT_TRUE(t.consistently_oriented);
}

// A torus has chi = 0 and genus 1.
TEST(Topology, TorusIsGenusOne) {
  auto t = analyze_topology(torus(3.0, 1.0, 24, 12));
  EXPECT_EQ(t.euler, 0);
  EXPECT_EQ(t.genus, 1);
  EXPECT_EQ(t.vertices, 24u * 12u);
  EXPECT_EQ(t.edges, 3u * 24u * 12u);
  EXPECT_EQ(t.faces, 2u * 24u * 12u);
}

// A disk has chi = 1 and one boundary loop, so g = (2 - 1 - 1) / 2 = 0.
TEST(Topology, DiskIsGenusZeroWithOneBoundaryLoop) {
  auto t = analyze_topology(disk(1.0, 4, 12));
  EXPECT_EQ(t.euler, 1);
  EXPECT_EQ(t.boundary_loops, 1u);
  EXPECT_EQ(t.boundary_edges, 12u);
  EXPECT_FALSE(t.closed);
  EXPECT_TRUE(t.manifold);
  EXPECT_EQ(t.genus, 0);
}

// An open cylinder has chi = 0 and two boundary loops: genus 0 (not 1, as chi alone would say).
TEST(Topology, OpenCylinderIsGenusZeroWithTwoBoundaryLoops) {
  auto t = analyze_topology(open_cylinder(1.0, 3.0, 16, 5));
  EXPECT_EQ(t.euler, 0);
  EXPECT_EQ(t.boundary_loops, 2u);
  EXPECT_EQ(t.genus, 0);
}

// Two tori joined by a tube (a double torus) have chi = -2 and genus 2.
TEST(Topology, DoubleTorusIsGenusTwo) {
  auto t = analyze_topology(torus_chain(2, 3.0, 1.0, 16, 8, 10.0));
  EXPECT_EQ(t.euler, -2);
  EXPECT_EQ(t.genus, 2);
  EXPECT_EQ(t.components.size(), 1u);
  EXPECT_TRUE(t.closed);
  EXPECT_TRUE(t.manifold);
  EXPECT_TRUE(t.orientable);
}

// A chain of g tori has genus g for several g.
TEST(Topology, TorusChainGenusMatches) {
  for (int g : {1, 3, 7}) {
    auto t = analyze_topology(torus_chain(g, 3.0, 1.0, 12, 8, 10.0));
    EXPECT_EQ(t.genus, g) << "g=" << g;
    EXPECT_EQ(t.euler, 2 - 2 * g);
  }
}

// Two disjoint tori: 2 components of genus 1 each, total genus 2, but chi = 0 (not -2): the
// genus must be summed per component, never derived from the total chi.
TEST(Topology, TwoDisjointToriSumGenusPerComponent) {
  auto t = analyze_topology(disjoint_union(torus(3, 1, 16, 8), translated(torus(3, 1, 16, 8), 20, 0, 0)));
  EXPECT_EQ(t.components.size(), 2u);
  EXPECT_EQ(t.euler, 0);
  ASSERT_EQ(t.components.size(), 2u);
  EXPECT_EQ(t.components[0].genus, 1);
  EXPECT_EQ(t.components[1].genus, 1);
  EXPECT_EQ(t.genus, 2);
}

// Components are listed largest first and face_component agrees with that order.
TEST(Topology, ComponentsSortedLargestFirst) {
  auto m = disjoint_union(sphere(1, 6, 3), torus(3, 1, 20, 10));
  auto t = analyze_topology(m);
  ASSERT_EQ(t.components.size(), 2u);
  EXPECT_GT(t.components[0].faces, t.components[1].faces);
  EXPECT_EQ(t.components[0].genus, 1);
  EXPECT_EQ(t.face_component.back(), 0);  // the torus triangles come last in m
  EXPECT_EQ(t.face_component.front(), 1);
}

// An edge with three triangles is non-manifold; its two end vertices are non-manifold; genus undefined.
TEST(Topology, ThreeTrianglesOnOneEdgeAreNonManifold) {
  TriangleList m;
  m.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
  m.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
  auto t = analyze_topology(m);
  EXPECT_EQ(t.nonmanifold_edges, 1u);
  EXPECT_EQ(t.nonmanifold_vertices, 2u);
  EXPECT_FALSE(t.manifold);
  EXPECT_FALSE(t.genus.has_value());
  ASSERT_EQ(t.example_nonmanifold_edges.size(), 1u);
  EXPECT_EQ(t.example_nonmanifold_edges[0], (std::array<int, 2>{0, 1}));
}

// Two tetrahedra sharing one vertex (a bowtie) make exactly one non-manifold vertex.
TEST(Topology, BowtieVertexIsNonManifold) {
  TriangleList tet;
  tet.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  tet.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  TriangleList two = disjoint_union(tet, translated(tet, -1, -1, -1));
  // Glue vertex 4+3 (the second tet's apex at (-1,-1,0)) ... instead weld second tet's vertex 1 onto vertex 0.
  two.points[5] = two.points[0];
  for (auto& tri : two.triangles)
    for (int& v : tri)
      if (v == 5) v = 0;
  auto t = analyze_topology(two);
  EXPECT_EQ(t.nonmanifold_edges, 0u);
  EXPECT_EQ(t.nonmanifold_vertices, 1u);
  EXPECT_EQ(t.example_nonmanifold_vertices.at(0), 0);
  EXPECT_EQ(t.components.size(), 1u);  // connected through the shared vertex
  EXPECT_EQ(t.unreferenced_vertices, 1u);
}

// A Moebius strip is a manifold with one boundary loop that is not orientable.
TEST(Topology, MoebiusStripIsNotOrientable) {
  TriangleList m;
  const int n = 12;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * 3.14159265358979 * i / n, w = 0.3;
    const double c = std::cos(a / 2) * w;
    m.points.push_back({(1 + c) * std::cos(a), (1 + c) * std::sin(a), std::sin(a / 2) * w});
    m.points.push_back({(1 - c) * std::cos(a), (1 - c) * std::sin(a), -std::sin(a / 2) * w});
  }
  for (int i = 0; i < n; ++i) {
    int a0 = 2 * i, a1 = 2 * i + 1, b0 = 2 * (i + 1), b1 = 2 * (i + 1) + 1;
    if (i == n - 1) {  // the half twist: the strip closes with its two sides swapped
      b0 = 1;
      b1 = 0;
    }
    m.triangles.push_back({a0, b0, b1});
    m.triangles.push_back({a0, b1, a1});
  }
  auto t = analyze_topology(m);
  EXPECT_TRUE(t.manifold);
  EXPECT_FALSE(t.orientable);
  EXPECT_EQ(t.boundary_loops, 1u);
  EXPECT_FALSE(t.genus.has_value());
}

// Flipping one triangle of a sphere is detected as inconsistent orientation (still orientable).
TEST(Topology, FlippedTriangleIsInconsistentButOrientable) {
  auto m = sphere(1, 8, 4);
  std::swap(m.triangles[5][1], m.triangles[5][2]);
  auto t = analyze_topology(m);
  EXPECT_EQ(t.inconsistent_edges, 3u);
  EXPECT_TRUE(t.orientable);
  EXPECT_FALSE(t.consistently_oriented);
  EXPECT_EQ(t.genus, 0);
}

// Bounding box and mean edge length are measured on referenced vertices only.
TEST(Topology, BoundingBoxAndMeanEdgeLength) {
  TriangleList m;
  m.points = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {100, 100, 100}};
  m.triangles = {{0, 1, 2}};
  auto t = analyze_topology(m);
  EXPECT_EQ(t.bbox_max[0], 2.0);
  EXPECT_EQ(t.bbox_max[2], 0.0);
  EXPECT_NEAR(t.mean_edge_length, (2 + 2 + std::sqrt(8.0)) / 3, 1e-12);
  EXPECT_EQ(t.vertices, 3u);
  EXPECT_EQ(t.unreferenced_vertices, 1u);
}

// The OpenMesh path gives the same report as the index path.
TEST(Topology, OpenMeshAndIndexPathsAgree) {
  auto tl = torus_chain(3, 3, 1, 12, 8, 10);
  auto mesh = to_mesh(tl);
  auto a = analyze_topology(tl), b = analyze_topology(mesh);
  EXPECT_EQ(a.vertices, b.vertices);
  EXPECT_EQ(a.edges, b.edges);
  EXPECT_EQ(a.faces, b.faces);
  EXPECT_EQ(a.genus, b.genus);
  EXPECT_TRUE(b.consistently_oriented);
}

}  // namespace
}  // namespace cf
