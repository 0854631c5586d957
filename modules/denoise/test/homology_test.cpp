// Z2 homology annotations (tree-cotree) and the Z2 span used to quotient out cut classes.
#include <gtest/gtest.h>

#include <functional>
#include <thread>

#include "colonflat/core/synthetic.h"
#include "colonflat/denoise/homology.h"

namespace cf {
namespace {

using namespace synthetic;

std::vector<std::uint64_t> class_of(const Mesh& m, const HomologyBasis& hb, const std::vector<int>& loop) {
  std::vector<std::uint64_t> c(hb.words(), 0);
  for (std::size_t i = 0; i < loop.size(); ++i) {
    auto h = m.find_halfedge(Mesh::VertexHandle(loop[i]), Mesh::VertexHandle(loop[(i + 1) % loop.size()]));
    EXPECT_TRUE(h.is_valid());
    xor_into(c.data(), hb.edge_class(m.edge_handle(h)), hb.words());
  }
  return c;
}

// Every face boundary sums to zero: annotations are cocycles, as a homology class must be.
void expect_face_boundaries_zero(const Mesh& m, const HomologyBasis& hb) {
  for (auto f : m.faces()) {
    std::vector<std::uint64_t> c(hb.words(), 0);
    for (auto e : m.fe_range(f)) xor_into(c.data(), hb.edge_class(e), hb.words());
    ASSERT_TRUE(is_zero(c.data(), hb.words())) << "face " << f.idx();
  }
}

// A sphere has rank 0 and an empty pruned cut graph.
TEST(DenoiseHomology, SphereHasNoClasses) {
  Mesh m = to_mesh(sphere(1, 12, 6));
  HomologyBasis hb;
  hb.build(m);
  EXPECT_EQ(hb.rank(), 0);
  EXPECT_TRUE(hb.pruned_cut_graph_vertices().empty());
}

// A torus has rank 2; its meridian and longitude have independent nonzero classes; faces sum to 0.
TEST(DenoiseHomology, TorusGenerators) {
  const int nu = 12, nv = 8;
  Mesh m = to_mesh(torus(3, 1, nu, nv));
  HomologyBasis hb;
  hb.build(m);
  EXPECT_EQ(hb.rank(), 2);
  expect_face_boundaries_zero(m, hb);
  std::vector<int> meridian, longitude;
  for (int j = 0; j < nv; ++j) meridian.push_back(0 * nv + j);
  for (int i = 0; i < nu; ++i) longitude.push_back(i * nv + 0);
  auto a = class_of(m, hb, meridian), b = class_of(m, hb, longitude);
  EXPECT_FALSE(is_zero(a.data(), hb.words()));
  EXPECT_FALSE(is_zero(b.data(), hb.words()));
  EXPECT_NE(a, b);
  EXPECT_FALSE(hb.pruned_cut_graph_vertices().empty());
}

// The neck loop between two tori is separating: its class is zero, while each torus's meridian is not.
TEST(DenoiseHomology, NeckOfDoubleTorusIsZero) {
  Mesh m = to_mesh(torus_chain(2, 3, 1, 16, 8, 10));
  HomologyBasis hb;
  hb.build(m);
  EXPECT_EQ(hb.rank(), 4);
  expect_face_boundaries_zero(m, hb);
  // Hole corners of the +x hole of torus 0: grid (0,0), (1,0), (1,1), (0,1) with nv = 8.
  std::vector<int> neck = {0 * 8 + 0, 1 * 8 + 0, 1 * 8 + 1, 0 * 8 + 1};
  auto c = class_of(m, hb, neck);
  EXPECT_TRUE(is_zero(c.data(), hb.words()));
  std::vector<int> meridian;
  for (int j = 0; j < 8; ++j) meridian.push_back(4 * 8 + j);  // u index 4 of torus 0
  auto d = class_of(m, hb, meridian);
  EXPECT_FALSE(is_zero(d.data(), hb.words()));
}

// An open cylinder (two boundary loops) has rank 0: its circumference separates it.
TEST(DenoiseHomology, OpenCylinderCircumferenceSeparates) {
  Mesh m = to_mesh(open_cylinder(1, 4, 12, 6));
  HomologyBasis hb;
  hb.build(m);
  EXPECT_EQ(hb.rank(), 0);
}

// A torus with a hole keeps rank 2 (the boundary is closed by a virtual face).
TEST(DenoiseHomology, TorusWithHoleKeepsRankTwo) {
  auto t = torus(3, 1, 12, 8);
  t.triangles.erase(t.triangles.begin() + 10);
  Mesh m = to_mesh(t);
  HomologyBasis hb;
  hb.build(m);
  EXPECT_EQ(hb.rank(), 2);
  expect_face_boundaries_zero(m, hb);
}

// A build whose cut-graph pruning runs on a helper thread beside the annotations (counted: the
// helper ran it) gives the one-thread build's rank, every edge's class, cut graph and pruned cut
// graph, on a chain of 3 tori with a hole (boundary: a virtual face) - an unequal split would show.
TEST(DenoiseHomology, BuildOnTwoThreadsIsTheOneThreadBuild) {
  auto t = torus_chain(3, 3, 1, 16, 8, 10);
  t.triangles.erase(t.triangles.begin() + 40);
  const Mesh m = to_mesh(t);
  HomologyBasis one, two;
  one.build(m);
  int on_helper = 0;
  two.build(m, [&](const std::function<void()>& mine, const std::function<void()>& theirs) {
    std::thread helper([&] {
      theirs();
      ++on_helper;
    });
    mine();
    helper.join();
  });
  EXPECT_EQ(one.builds_on_two_threads(), 0);
  EXPECT_EQ(two.builds_on_two_threads(), 1);
  EXPECT_EQ(on_helper, 1);
  ASSERT_EQ(two.rank(), 6);
  ASSERT_EQ(two.rank(), one.rank());
  for (auto e : m.edges())
    ASSERT_EQ(std::vector<std::uint64_t>(two.edge_class(e), two.edge_class(e) + two.words()),
              std::vector<std::uint64_t>(one.edge_class(e), one.edge_class(e) + one.words()))
        << e.idx();
  EXPECT_EQ(two.cut_graph_edges(), one.cut_graph_edges());
  EXPECT_EQ(two.pruned_cut_graph_edges(), one.pruned_cut_graph_edges());
  EXPECT_EQ(two.pruned_cut_graph_vertices(), one.pruned_cut_graph_vertices());
  EXPECT_FALSE(two.pruned_cut_graph_vertices().empty());
  expect_face_boundaries_zero(m, two);
}

// Z2Span: membership, reduction and independence.
TEST(DenoiseHomology, Z2SpanEchelon) {
  Z2Span s(2);
  std::uint64_t a[2] = {0b101, 0}, b[2] = {0b011, 1}, c[2] = {0b110, 1}, d[2] = {0, 2};
  EXPECT_TRUE(s.insert(a));
  EXPECT_TRUE(s.insert(b));
  EXPECT_TRUE(s.contains(c));  // a ^ b
  EXPECT_FALSE(s.insert(c));
  EXPECT_FALSE(s.contains(d));
  EXPECT_TRUE(s.insert(d));
  EXPECT_EQ(s.dimension(), 3);
}

}  // namespace
}  // namespace cf
