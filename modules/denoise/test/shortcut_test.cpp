// "Shortcut first" (docs/denoise.md, issue 26 session 28): a U-shaped tube whose two legs are fused
// by a slab (a fused contact) must keep its whole length when the slab's opening is wider than the
// tube's girth, and a wide pick whose cut lengthens the end-to-end path is cut as before.
#include <gtest/gtest.h>

#include <array>
#include <map>
#include <vector>

#include "colonflat/core/geodesic_ball.h"
#include "colonflat/core/synthetic.h"
#include "colonflat/denoise/denoise.h"

namespace cf {
namespace {

struct Box {
  int x0, x1, y0, y1, z0, z1;  // voxels [x0, x1) x [y0, y1) x [z0, z1), 1 mm each
};

// The boundary of a union of boxes of 1 mm voxels as a closed triangle mesh (each exposed voxel
// face two triangles, normals outwards). The boxes must meet face to face (no edge-only contact).
Mesh voxel_surface(const std::vector<Box>& boxes, int nx, int ny, int nz) {
  auto inside = [&](int x, int y, int z) {
    for (const Box& b : boxes)
      if (x >= b.x0 && x < b.x1 && y >= b.y0 && y < b.y1 && z >= b.z0 && z < b.z1) return true;
    return false;
  };
  TriangleList t;
  std::map<std::array<int, 3>, int> corner;
  auto id = [&](std::array<int, 3> c) {
    auto [it, fresh] = corner.emplace(c, int(t.points.size()));
    if (fresh) t.points.push_back({double(c[0]), double(c[1]), double(c[2])});
    return it->second;
  };
  for (int x = 0; x < nx; ++x)
    for (int y = 0; y < ny; ++y)
      for (int z = 0; z < nz; ++z) {
        if (!inside(x, y, z)) continue;
        for (int d = 0; d < 3; ++d)
          for (int s : {-1, 1}) {
            std::array<int, 3> n{x, y, z};
            n[d] += s;
            if (inside(n[0], n[1], n[2])) continue;
            const int u = (d + 1) % 3, v = (d + 2) % 3;
            std::array<int, 3> c0{x, y, z};
            if (s > 0) ++c0[d];
            std::array<int, 3> c1 = c0, c2 = c0, c3 = c0;
            ++c1[u];
            ++c2[u], ++c2[v];
            ++c3[v];
            const int a = id(c0), b = id(c1), c = id(c2), e = id(c3);
            if (s > 0) t.triangles.push_back({a, b, c}), t.triangles.push_back({a, c, e});
            else t.triangles.push_back({a, c, b}), t.triangles.push_back({a, e, c});
          }
      }
  return synthetic::to_mesh(t);
}

// A U of square tubes (side 6 mm, girth 24 mm): legs x in [0, 100) at y in [0, 6) and [10, 16),
// the bend at x in [100, 106); the legs fused over x in [65, 65 + contact) by a slab filling the
// 4 mm gap. Its centreline is about 100 + 11 + 100 = 211 mm; through the slab the legs' tips are
// 134 mm apart, still the farthest points (the bend is ~116 mm from a tip); the window between
// slab and bend is at least 21 mm long, so the loop round it (>= 50 mm) is not the shortest.
constexpr double kCentreline = 211.0;
Mesh fused_u(int contact) {
  return voxel_surface({{1, 101, 1, 7, 1, 7}, {1, 101, 11, 17, 1, 7}, {101, 107, 1, 17, 1, 7},
                        {66, 66 + contact, 7, 11, 1, 7}},
                       110, 20, 10);
}

// Surface distance between the result's two farthest points (two farthest-point sweeps).
double end_to_end(const Mesh& m) {
  std::vector<double> d;
  const std::vector<int> first = vertices_within(m, {Mesh::VertexHandle(0)}, 1e9, &d);
  const std::vector<int> second = vertices_within(m, {Mesh::VertexHandle(first.back())}, 1e9, &d);
  return d.back();
}

DenoiseOptions shortcut_on() {
  DenoiseOptions o;
  o.shortcut_diameter = 5;  // the 6 mm tube's girth is 8.5 mm wide
  return o;
}

// The premise: a slab 14 mm long (opening ~40 mm) is wider than the girth (24 mm), so the plain
// greedy cuts the tube on the stretch the slab bypasses and the ends are joined through the slab.
TEST(DenoiseShortcut, PlainGreedyCutsTheBypassedTube) {
  const Mesh m = fused_u(14);
  const DenoiseResult r = denoise(m, DenoiseOptions{});
  ASSERT_EQ(r.after.genus, 0);
  ASSERT_EQ(r.loops.size(), 1u);
  EXPECT_LT(r.loops[0].length, 30.0);     // the girth, not the slab's opening
  EXPECT_LT(end_to_end(r.mesh), 0.7 * kCentreline);  // the ends meet through the slab
}

// With the rule the slab's opening is cut instead: genus 0 and the end-to-end path runs along the
// whole U (at least 0.85 of its centreline; through the slab it is 134 mm, 0.64 of it).
TEST(DenoiseShortcut, FusedContactIsCutNotTheTube) {
  const Mesh m = fused_u(14);
  const DenoiseResult r = denoise(m, shortcut_on());
  ASSERT_EQ(r.after.genus, 0);
  ASSERT_EQ(r.loops.size(), 1u);
  EXPECT_GT(r.loops[0].length, 30.0);  // round the slab
  EXPECT_GT(end_to_end(r.mesh), 0.85 * kCentreline);
  EXPECT_EQ(r.report["search"]["shortcut_loops_replaced"], 1);
}

// A narrow slab (2 mm: opening ~16 mm, below the girth) is the greedy's pick and its cut lengthens
// the end-to-end path: the rule tests it and keeps it, the same loop and mesh as without the rule.
TEST(DenoiseShortcut, PickThatLengthensThePathIsKept) {
  const Mesh m = fused_u(2);
  const DenoiseResult plain = denoise(m, DenoiseOptions{});
  const DenoiseResult r = denoise(m, shortcut_on());
  ASSERT_EQ(r.loops.size(), 1u);
  ASSERT_EQ(plain.loops.size(), 1u);
  EXPECT_EQ(r.report["search"]["shortcut_tests"], 1);
  EXPECT_EQ(r.report["search"]["shortcut_loops_replaced"], 0);
  EXPECT_EQ(r.loops[0].vertex_ids, plain.loops[0].vertex_ids);
  EXPECT_EQ(r.mesh.n_faces(), plain.mesh.n_faces());
  EXPECT_GT(end_to_end(r.mesh), 0.85 * kCentreline);
}

}  // namespace
}  // namespace cf
