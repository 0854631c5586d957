// The compact adjacency (vertex_adjacency.h): the same neighbours in the same order, the same
// halfedges and the same edge lengths to the bit as OpenMesh's halfedge walk, on a fresh mesh,
// after surgeries and after an undo; searches reading it give the same results as on halfedges.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <thread>

#include "colonflat/core/synthetic.h"
#include "colonflat/denoise/face_grid.h"
#include "colonflat/denoise/homology.h"
#include "colonflat/denoise/loop_search.h"
#include "colonflat/denoise/surgery.h"
#include "colonflat/denoise/vertex_adjacency.h"

namespace cf {
namespace {

using namespace synthetic;
using VH = Mesh::VertexHandle;

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// The first vertex whose list differs from the halfedge walk (-1: none; the vertex count when the
// counts differ).
int first_difference(const VertexAdjacency& adj, const Mesh& m) {
  if (adj.vertices() != m.n_vertices()) return static_cast<int>(m.n_vertices());
  for (auto v : m.vertices()) {
    const VertexAdjacency::Range r = adj.out(v.idx());
    const VertexAdjacency::Out* o = r.begin();
    for (auto h : m.voh_range(v)) {
      const auto w = m.to_vertex_handle(h);
      if (o == r.end() || o->to != w.idx() || o->halfedge != h.idx() ||
          !same_bits(o->length, (m.point(w) - m.point(v)).norm()))
        return v.idx();
      ++o;
    }
    if (o != r.end()) return v.idx();
  }
  return -1;
}

// A torus chain with its points moved a little, so that no two edges have the same length.
Mesh bumpy_chain(int tori) {
  Mesh m = to_mesh(torus_chain(tori, 3, 1, 16, 8, 10));
  for (auto v : m.vertices()) m.point(v) *= 1.0 + 0.03 * std::sin(7.0 * v.idx());
  return m;
}

std::vector<VH> meridian(int i, int nv) {
  std::vector<VH> l;
  for (int j = 0; j < nv; ++j) l.push_back(VH(i * nv + j));
  return l;
}

// Built on a mesh: every vertex's outgoing halfedges in voh_range() order, with their to-vertices
// and (p_to - p_from).norm() to the bit.
TEST(DenoiseVertexAdjacency, BuildMatchesHalfedgeWalk) {
  const Mesh m = bumpy_chain(2);
  const VertexAdjacency adj(m);
  EXPECT_EQ(first_difference(adj, m), -1);
  EXPECT_EQ(adj.stored(), m.n_halfedges());
}

// Built in two halves (the second on another thread): the same lists, entry for entry, as one build.
TEST(DenoiseVertexAdjacency, TwoHalvesBuildTheSameBlock) {
  const Mesh m = bumpy_chain(2);
  const VertexAdjacency one(m);
  VertexAdjacency two;
  two.build(m, [](const std::function<void()>& mine, const std::function<void()>& theirs) {
    std::thread t(theirs);
    mine();
    t.join();
  });
  EXPECT_EQ(first_difference(two, m), -1);
  ASSERT_EQ(two.stored(), one.stored());
  for (std::size_t i = 0; i < one.stored(); ++i) {
    ASSERT_EQ(one.entries()[i].to, two.entries()[i].to) << i;
    ASSERT_EQ(one.entries()[i].halfedge, two.entries()[i].halfedge) << i;
  }
}

// After two surgeries (concentric caps, then caps triangulated against a guard) and the undo of
// the second, refresh() with touched_by_surgery() gives every list the halfedge walk gives; the
// lists left stale, or refreshed with new vertices only, do not (the surgeries changed them).
TEST(DenoiseVertexAdjacency, RefreshFollowsSurgeryAndUndo) {
  Mesh m = bumpy_chain(2);
  VertexAdjacency adj(m);
  const SurgeryResult first = cut_and_cap(m, meridian(4, 8), SurgeryOptions{});
  VertexAdjacency stale = adj, added_only = adj;
  added_only.refresh(m, {});
  EXPECT_NE(first_difference(stale, m), -1);
  EXPECT_NE(first_difference(added_only, m), -1);
  adj.refresh(m, touched_by_surgery(m, first.undo));
  EXPECT_EQ(first_difference(adj, m), -1);
  // The second torus's meridian, capped against a guard (triangulated caps where clean).
  FaceGrid guard(m, 2.0);
  SurgeryOptions o;
  o.guard = &guard;
  const SurgeryResult second = cut_and_cap(m, meridian(16 + 4, 8), o);
  adj.refresh(m, touched_by_surgery(m, second.undo));
  EXPECT_EQ(first_difference(adj, m), -1);
  const std::vector<int> touched = touched_by_surgery(m, second.undo);
  undo_surgery(m, second.undo);
  stale = adj;
  stale.refresh(m, {});
  EXPECT_NE(first_difference(stale, m), -1);
  adj.refresh(m, touched);
  EXPECT_EQ(first_difference(adj, m), -1);
}

// A moved vertex changes its own lengths and its neighbours': touched_by_surgery() lists them.
TEST(DenoiseVertexAdjacency, MovedVertexRefreshesItsNeighbours) {
  Mesh m = bumpy_chain(1);
  VertexAdjacency adj(m);
  SurgeryUndo undo;
  undo.vertices = m.n_vertices();
  undo.edges = m.n_edges();
  undo.faces = m.n_faces();
  const VH v(37);
  undo.positions.push_back({v, m.point(v)});
  m.set_point(v, m.point(v) * 1.01);
  EXPECT_NE(first_difference(adj, m), -1);
  adj.refresh(m, touched_by_surgery(m, undo));
  EXPECT_EQ(first_difference(adj, m), -1);
}

// Same search results on the compact adjacency as on the halfedges: value, ends, truncation,
// frontier bound, settled vertices in order with their distances to the bit, the extracted loop;
// single-source runs (span and cochain mode) and group runs, on a mesh after a surgery.
TEST(DenoiseVertexAdjacency, SearchesGiveTheSameResults) {
  Mesh m = bumpy_chain(3);
  cut_and_cap(m, meridian(4, 8), SurgeryOptions{});
  const VertexAdjacency adj(m);
  HomologyBasis hb;
  hb.build(m);
  Z2Span span(hb.words());
  FundamentalCycleSearch walk(m, hb, span), compact(m, hb, span);
  compact.set_adjacency(&adj);
  auto expect_same = [&](const CycleCandidate& a, const CycleCandidate& b, const std::string& what) {
    EXPECT_EQ(a.found, b.found) << what;
    EXPECT_TRUE(same_bits(a.value, b.value)) << what;
    EXPECT_EQ(a.u, b.u) << what;
    EXPECT_EQ(a.v, b.v) << what;
    EXPECT_EQ(a.truncated, b.truncated) << what;
    EXPECT_TRUE(same_bits(a.frontier_bound, b.frontier_bound)) << what;
    ASSERT_EQ(walk.last_settled_vertices(), compact.last_settled_vertices()) << what;
    for (int x : walk.last_settled_vertices()) ASSERT_TRUE(same_bits(walk.distance(x), compact.distance(x))) << what;
    if (a.found) EXPECT_EQ(walk.extract(a), compact.extract(b)) << what;
  };
  for (int s : {3, 100, 250, 400}) {
    for (double limit : {2.0, 8.0, 100.0}) {
      const std::string what = "source " + std::to_string(s) + " limit " + std::to_string(limit);
      expect_same(walk.run(VH(s), limit, nullptr, true), compact.run(VH(s), limit, nullptr, true), what);
    }
  }
  const std::vector<std::uint8_t> cochain = crossing_cochain(m, meridian(20, 8));
  walk.set_cochain(&cochain);
  compact.set_cochain(&cochain);
  expect_same(walk.run(VH(200), 100), compact.run(VH(200), 100), "cochain");
  walk.set_cochain(nullptr);
  compact.set_cochain(nullptr);
  const std::vector<int> roots{160, 161, 162}, parents{-1, m.find_halfedge(VH(160), VH(161)).idx(),
                                                       m.find_halfedge(VH(161), VH(162)).idx()};
  expect_same(walk.run_group(roots, parents, 100), compact.run_group(roots, parents, 100), "group");
}

}  // namespace
}  // namespace cf
