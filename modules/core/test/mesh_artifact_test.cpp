// The mesh artifact's stand-in (the triangle list `colonflat run` holds a mesh as while no stage
// needs its halfedges): lossless, refused where it would lose something, written as the mesh.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "colonflat/core/mesh_artifact.h"
#include "colonflat/testdata/synthetic.h"
#include "colonflat/testing/temp_dir.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

std::string bytes_of(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// A genus-2 surface whose face order is not the order of its vertices: faces of two tori, interleaved.
Mesh two_tori() {
  TriangleList a = synthetic::torus(30, 10, 24, 12), b = synthetic::translated(synthetic::torus(20, 6, 18, 10), 80, 0, 0);
  TriangleList t = a;
  const int n = static_cast<int>(a.points.size());
  t.points.insert(t.points.end(), b.points.begin(), b.points.end());
  t.triangles.clear();
  for (std::size_t i = 0; i < std::max(a.triangles.size(), b.triangles.size()); ++i) {
    if (i < b.triangles.size()) t.triangles.push_back({b.triangles[i][0] + n, b.triangles[i][1] + n, b.triangles[i][2] + n});
    if (i < a.triangles.size()) t.triangles.push_back(a.triangles[i]);
  }
  return synthetic::to_mesh(t);
}

// compact gives to_triangle_list of the mesh, and expand gives back a mesh with the same points,
// the same faces in the same order and corners, and the same edges and halfedge connectivity counts.
TEST(MeshArtifact, StandInExpandsToTheSameMesh) {
  const Mesh mesh = two_tori();
  const std::optional<std::any> stand_in = mesh_artifact().compact(std::any(mesh));
  ASSERT_TRUE(stand_in.has_value());
  const TriangleList& list = std::any_cast<const TriangleList&>(*stand_in);
  EXPECT_EQ(list.triangles, mesh_triangles(mesh));
  const Mesh back = std::any_cast<Mesh>(mesh_artifact().expand(*stand_in));
  ASSERT_EQ(back.n_vertices(), mesh.n_vertices());
  EXPECT_EQ(back.n_edges(), mesh.n_edges());
  EXPECT_EQ(mesh_triangles(back), mesh_triangles(mesh));
  for (auto v : mesh.vertices()) {
    EXPECT_EQ(back.point(v), mesh.point(v));
    EXPECT_EQ(back.valence(v), mesh.valence(v));
  }
  EXPECT_EQ(analyze_topology(back).genus, std::optional<int>(2));
}

// A mesh that would lose something as a list is not compacted: one with a face marked deleted
// (not yet collected), and one still carrying the reader's orientation note for its stage.
TEST(MeshArtifact, NotCompactedWithDeletedElementsOrTheReadersNote) {
  Mesh deleted = synthetic::to_mesh(synthetic::sphere(10, 12, 8));
  deleted.delete_face(Mesh::FaceHandle(0), false);
  EXPECT_FALSE(mesh_artifact().compact(std::any(deleted)).has_value());
  Mesh noted = synthetic::to_mesh(synthetic::sphere(10, 12, 8));
  OpenMesh::MPropHandleT<std::string> h;
  noted.add_property(h, kReadOrientationProperty);
  noted.property(h) = "{}";
  EXPECT_FALSE(mesh_artifact().compact(std::any(noted)).has_value());
  noted.remove_property(h);
  EXPECT_TRUE(mesh_artifact().compact(std::any(noted)).has_value());
}

// The artifact's writer writes the stand-in to the very bytes it writes for the mesh, in every
// format (.vtp and .vtk from the list's PolyData, the others through the halfedge mesh).
TEST(MeshArtifact, StandInWritesTheSameFileAsTheMesh) {
  testing::TempDir tmp;
  const Mesh mesh = two_tori();
  const std::any stand_in = *mesh_artifact().compact(std::any(mesh));
  for (const std::string ext : {".vtp", ".vtk", ".off", ".obj", ".ply", ".stl"}) {
    const fs::path from_mesh = tmp.path() / ("mesh" + ext), from_list = tmp.path() / ("list" + ext);
    mesh_artifact().write(std::any(mesh), from_mesh, from_mesh);
    mesh_artifact().write(stand_in, from_list, from_list);
    const std::string a = bytes_of(from_mesh);
    EXPECT_GT(a.size(), 1000u) << ext;
    EXPECT_EQ(a, bytes_of(from_list)) << ext;
  }
}

}  // namespace
}  // namespace cf
