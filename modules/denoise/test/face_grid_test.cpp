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

}  // namespace
}  // namespace cf
