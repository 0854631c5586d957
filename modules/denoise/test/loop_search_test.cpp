// Loop search: the first loop of the exact method equals the brute-force shortest
// non-separating cycle; loop types on a torus.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "brute_force.h"
#include "colonflat/core/mesh_io.h"
#include "colonflat/core/synthetic.h"
#include "colonflat/denoise/denoise.h"
#include "colonflat/denoise/loop_search.h"

namespace cf {
namespace {

using namespace synthetic;
using VH = Mesh::VertexHandle;

Mesh shared_mesh(const std::string& name) {
  return load_mesh(std::string(COLONFLAT_SHARED_DIR) + "/meshes/" + name).mesh;
}

// First loop of `exact` (genus reduced by one) against exhaustive search on the same mesh.
void expect_first_loop_is_shortest(const Mesh& m, const std::string& what) {
  DenoiseOptions o;
  o.target_genus = *analyze_topology(m).genus - 1;
  DenoiseResult r = denoise(m, o);
  ASSERT_EQ(r.loops.size(), 1u) << what;
  const double mine = r.loops[0].length;
  std::vector<VH> ref_loop;
  const double ref = testing::brute_force_shortest_nonseparating(m, mine * (1 + 1e-9) + 1e-12, &ref_loop);
  EXPECT_NEAR(mine, ref, 1e-9 * (1 + ref)) << what << ": exact " << mine << " vs brute force " << ref;
  // The exact loop is non-separating (checked by cutting and flooding, independently).
  std::vector<VH> loop;
  for (int id : r.loops[0].vertex_ids) loop.push_back(VH(id));
  EXPECT_FALSE(testing::loop_separates(m, loop)) << what;
}

// Brute force agrees on a torus (minimum = a meridian polygon), a double torus and a genus-3 chain.
TEST(DenoiseLoopSearch, FirstLoopMatchesBruteForceSynthetic) {
  Mesh t = to_mesh(torus(3, 1, 24, 10));
  expect_first_loop_is_shortest(t, "torus");
  // The meridian polygon with 10 sides of radius 1.
  DenoiseOptions o;
  auto r = denoise(t, o);
  EXPECT_NEAR(r.loops[0].length, 10 * 2 * std::sin(3.14159265358979 / 10), 1e-9);
  expect_first_loop_is_shortest(to_mesh(torus_chain(2, 3, 1, 16, 8, 10)), "double torus chain");
  expect_first_loop_is_shortest(to_mesh(torus_chain(3, 3.5, 1.2, 14, 8, 11)), "genus 3 chain");
}

// Brute force agrees on the small shared meshes (up to ~5K faces) of genus >= 1.
TEST(DenoiseLoopSearch, FirstLoopMatchesBruteForceSharedMeshes) {
  for (const char* name : {"eight.off", "fertility_1k.off", "knot.off", "double_torus.off", "torus.off"})
    expect_first_loop_is_shortest(shared_mesh(name), name);
}

// Every loop of the greedy sequence (not only the first) is the shortest non-separating cycle
// of the mesh it was cut on: after each surgery the kept lower bounds, the bounds reset near the
// caps and the new ring sources still find the global minimum (surgery on top of surgery).
TEST(DenoiseLoopSearch, EveryLoopMatchesBruteForceOnItsMesh) {
  for (const char* name : {"fertility_1k.off", "eight.off"}) {
    const Mesh m = shared_mesh(name);
    const int genus = *analyze_topology(m).genus;
    const DenoiseResult full = denoise(m, DenoiseOptions{});
    ASSERT_EQ(full.loops.size(), static_cast<std::size_t>(genus)) << name;
    for (int i = 0; i < genus; ++i) {
      DenoiseOptions o;
      o.target_genus = genus - i;  // the first i surgeries of the same greedy run
      const Mesh before = i == 0 ? m : denoise(m, o).mesh;
      const double mine = full.loops[i].length;
      const double ref = testing::brute_force_shortest_nonseparating(before, mine * (1 + 1e-9) + 1e-12);
      EXPECT_NEAR(mine, ref, 1e-9 * (1 + ref)) << name << " loop " << i;
    }
  }
}

// A late rebuild (genus left <= a quarter of the genus at the last build) happens on a surface
// too small for the work rule, and the loops after it, searched from the new cut graph with the
// bounds carried from the old sources, are still the shortest non-separating cycles of their
// meshes: a chain of 8 tori beside a large sphere (rebuilt at genus 2; loops 7 and 8 against
// brute force).
TEST(DenoiseLoopSearch, LateRebuildCarriesBoundsAndKeepsLoopsExact) {
  // The sphere (genus 0: no sources) holds most vertices, so the searches' work stays far below
  // the work rule's 2.5 vertex counts: only the late rule rebuilds.
  const Mesh m = to_mesh(disjoint_union(torus_chain(8, 3, 1, 14, 8, 9), translated(sphere(40, 80, 48), 0, 100, 0)));
  ASSERT_EQ(*analyze_topology(m).genus, 8);
  const DenoiseResult full = denoise(m, DenoiseOptions{});
  ASSERT_EQ(full.loops.size(), 8u);
  EXPECT_GE(full.report["search"]["homology_builds"].get<int>(), 2);
  for (int i = 6; i < 8; ++i) {
    DenoiseOptions o;
    o.target_genus = 8 - i;  // the first i surgeries of the same greedy run
    const Mesh before = denoise(m, o).mesh;
    const double mine = full.loops[i].length;
    const double ref = testing::brute_force_shortest_nonseparating(before, mine * (1 + 1e-9) + 1e-12);
    EXPECT_NEAR(mine, ref, 1e-9 * (1 + ref)) << "loop " << i;
  }
}

// On a torus (outward normals) a meridian bounds a disk inside the solid: handle; the inner
// equator bounds a disk across the hole, outside: tunnel.
TEST(DenoiseLoopSearch, HandleAndTunnelOnTorus) {
  const int nu = 24, nv = 12;
  Mesh m = to_mesh(torus(3, 1, nu, nv));
  std::vector<VH> mer, inner;
  for (int j = 0; j < nv; ++j) mer.push_back(VH(5 * nv + j));
  for (int i = 0; i < nu; ++i) inner.push_back(VH(i * nv + nv / 2));  // v = pi: inner equator
  EXPECT_EQ(classify_loop(m, mer), LoopType::kHandle);
  EXPECT_EQ(classify_loop(m, inner), LoopType::kTunnel);
  EXPECT_NEAR(loop_length(m, inner), nu * 2 * 2 * std::sin(3.14159265358979 / nu), 1e-9);
}

// The crossing cochain counts Z2 intersections: on a torus a meridian crosses the equator once
// and a parallel meridian or itself zero times; a longitude shifted by two rings too.
TEST(DenoiseLoopSearch, CrossingCochainCountsIntersections) {
  const int nu = 24, nv = 12;
  const Mesh m = to_mesh(torus(3, 1, nu, nv));
  auto meridian = [&](int i) {
    std::vector<VH> l;
    for (int j = 0; j < nv; ++j) l.push_back(VH(i * nv + j));
    return l;
  };
  auto parallel = [&](int j) {
    std::vector<VH> l;
    for (int i = 0; i < nu; ++i) l.push_back(VH(i * nv + j));
    return l;
  };
  auto crossings = [&](const std::vector<std::uint8_t>& x, const std::vector<VH>& loop) {
    int sum = 0;
    for (std::size_t i = 0; i < loop.size(); ++i)
      sum += x[m.edge_handle(m.find_halfedge(loop[i], loop[(i + 1) % loop.size()])).idx()];
    return sum % 2;
  };
  const auto across_meridian = crossing_cochain(m, meridian(5));
  EXPECT_EQ(crossings(across_meridian, parallel(0)), 1);
  EXPECT_EQ(crossings(across_meridian, parallel(7)), 1);
  EXPECT_EQ(crossings(across_meridian, meridian(5)), 0);
  EXPECT_EQ(crossings(across_meridian, meridian(9)), 0);
  const auto across_parallel = crossing_cochain(m, parallel(3));
  EXPECT_EQ(crossings(across_parallel, meridian(0)), 1);
  EXPECT_EQ(crossings(across_parallel, parallel(5)), 0);
}

// A multi-root search (tree edges of length 0) bounds F(t) from below for every root t, and its
// value is F(root) exactly when both tree paths of its cycle lead to the same root: roots along a
// stretch of the outer equator of a torus (every meridian through them has the same length) and
// of a bumpy torus, as a path and as a single root, compared with one search per root.
TEST(DenoiseLoopSearch, GroupSearchBoundsEveryRootAndIsExactAtItsRoot) {
  const int nu = 40, nv = 10;
  Mesh bumpy = to_mesh(torus(3, 1, nu, nv));
  for (auto v : bumpy.vertices()) bumpy.point(v) *= 1.0 + 0.05 * std::sin(3.0 * v.idx());
  const std::vector<Mesh> meshes{to_mesh(torus(3, 1, nu, nv)), bumpy};
  for (const Mesh& mesh : meshes) {
    const Mesh* m = &mesh;
    HomologyBasis hb;
    hb.build(*m);
    Z2Span span(hb.words());
    FundamentalCycleSearch search(*m, hb, span);
    for (int count : {1, 2, 6, 15}) {
      std::vector<int> roots, parents{-1};
      for (int i = 0; i < count; ++i) roots.push_back(i * nv);
      for (int i = 1; i < count; ++i) parents.push_back(m->find_halfedge(VH(roots[i - 1]), VH(roots[i])).idx());
      double own_min = kInf;
      std::vector<double> own(count);
      for (int i = 0; i < count; ++i) own_min = std::min(own_min, own[i] = search.run(VH(roots[i]), 100).value);
      const CycleCandidate g = search.run_group(roots, parents, 100);
      ASSERT_TRUE(g.found) << count;
      EXPECT_LE(g.value, own_min * (1 + 1e-12)) << count;
      const int root = search.root_of(g.u.idx());
      if (count == 1) EXPECT_EQ(root, roots[0]);
      if (root == search.root_of(g.v.idx())) {
        const int i = static_cast<int>(std::find(roots.begin(), roots.end(), root) - roots.begin());
        ASSERT_LT(i, count);
        EXPECT_NEAR(g.value, own[i], 1e-9 * own[i]) << count;
      }
    }
  }
}

// On genus-1 surfaces whose loop must be certified against many sources, the search switches to
// the two crossing families and the loop still equals the brute-force shortest one: a thin
// torus (a long handle: many sources on the cut graph) and the torus of the shared meshes.
TEST(DenoiseLoopSearch, CrossingFamiliesKeepTheLoopExact) {
  for (const auto& [m, what] : {std::pair{to_mesh(torus(6, 0.7, 90, 12)), "thin torus"},
                                std::pair{shared_mesh("torus.off"), "torus.off"}}) {
    const DenoiseResult r = denoise(m, DenoiseOptions{});
    ASSERT_EQ(r.loops.size(), 1u) << what;
    const double ref = testing::brute_force_shortest_nonseparating(m, r.loops[0].length * (1 + 1e-9) + 1e-12);
    EXPECT_NEAR(r.loops[0].length, ref, 1e-9 * (1 + ref)) << what;
    EXPECT_GE(r.report["search"]["crossing_family_switches"].get<int>(), 1) << what;
  }
}

// Proves that the crossing families take loop A's length U as the known bound: on a thin torus
// (meridian A 4.37 mm; the cycles crossing it >= the inner longitude, 33.3 mm = 7.6 U) Z is found
// within 4 searches of A's family (limits 2U, then doubled: 4U, 8U >= 7.6 U); without A's length
// A's sources are searched one by one with limits doubling from 10 mean edges (11 searches).
TEST(DenoiseLoopSearch, CrossingFamiliesSearchToTwiceLoopA) {
  const Mesh m = to_mesh(torus(6, 0.7, 90, 12));
  const DenoiseResult r = denoise(m, DenoiseOptions{});
  ASSERT_EQ(r.loops.size(), 1u);
  ASSERT_GE(r.report["search"]["crossing_family_switches"].get<int>(), 1);
  EXPECT_LE(r.report["search"]["crossing_searches_to_z"].get<long long>(), 4);
  const double ref = testing::brute_force_shortest_nonseparating(m, r.loops[0].length * (1 + 1e-9) + 1e-12);
  EXPECT_NEAR(r.loops[0].length, ref, 1e-9 * (1 + ref));
}

// Proves that Z's reroute is counted as a search of its own run alone: on the thin torus the
// inner longitude stays a tube width away from the meridian A except at its root, so the reroute
// finds a route (1 found), and its settled vertices are part of the alone and total counts.
TEST(DenoiseLoopSearch, ZRerouteIsCountedAlone) {
  const Mesh m = to_mesh(torus(6, 0.7, 90, 12));
  const DenoiseResult r = denoise(m, DenoiseOptions{});
  ASSERT_EQ(r.loops.size(), 1u);
  const auto& s = r.report["search"];
  EXPECT_EQ(s.at("z_reroutes_found").get<long long>(), 1);
  const long long reroute = s.at("z_reroute_settled").get<long long>();
  EXPECT_GT(reroute, 0);
  EXPECT_LE(reroute, static_cast<long long>(m.n_vertices()));
  EXPECT_LE(reroute, s["settled_vertices_alone"].get<long long>());
  EXPECT_LE(s["settled_vertices_alone"].get<long long>(), s["settled_vertices"].get<long long>());
}

}  // namespace
}  // namespace cf
