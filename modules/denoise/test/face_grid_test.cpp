// FaceGrid: intersections of new triangles with the surface and with each other.
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace cf
