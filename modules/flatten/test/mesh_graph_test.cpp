// The edge graph and the geodesic search of flatten (mesh_graph.cpp): a sub-surface's edges taken
// from its surface's are build_edges' own; the cap's search stops at its bound and is exact below it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <queue>
#include <random>

#include "../src/flatten_internal.h"
#include "colonflat/core/params.h"
#include "colonflat/core/synthetic.h"
#include "colonflat/flatten/synthetic_colon.h"

namespace cf {
namespace {

using namespace flat_detail;

Surface surface_of(const TriangleList& m) {
  Surface s;
  for (std::size_t v = 0; v < m.points.size(); ++v) {
    s.p.emplace_back(m.points[v][0], m.points[v][1], m.points[v][2]);
    s.src.push_back(int(v));
  }
  s.t.assign(m.triangles.begin(), m.triangles.end());
  return s;
}

void expect_same_edges(const Edges& a, const Edges& b) {
  EXPECT_EQ(a.ev, b.ev);
  EXPECT_EQ(a.ef, b.ef);
  EXPECT_EQ(a.fe, b.fe);
}

// sub_edges on a random 70 % of a closed colon's faces (edges that lose their first face, their
// second, or neither) equals build_edges of the sub-surface: same numbering, faces, opposite edges.
TEST(FlattenMeshGraph, SubEdgesEqualTheSubSurfacesOwnEdges) {
  const Surface s = surface_of(synthetic::colon(synthetic::colon_options(200, 15, 1.2, {})).mesh);
  const Edges E = build_edges(s.t);
  std::mt19937 rng(7);
  std::vector<char> keep(s.t.size());
  for (auto& k : keep) k = std::uniform_real_distribution<double>(0, 1)(rng) < 0.7;
  std::vector<int> new_of_old;
  const Surface sub = sub_surface(s, keep, &new_of_old);
  ASSERT_GT(sub.t.size(), s.t.size() / 2);
  expect_same_edges(sub_edges(E, keep, new_of_old), build_edges(sub.t));
}

// build_edges (corners bucketed by the edge's lower vertex, each bucket sorted by higher vertex and
// corner) numbers the edges as a stable global sort of every corner's (lo, hi) key does: edges by
// (lo, hi), an edge's faces in face order, each face's edge opposite each corner; on a closed colon
// whose faces are shuffled (so that buckets fill out of vertex order and an edge's faces far apart).
TEST(FlattenMeshGraph, EdgesAreNumberedAsAStableGlobalSortOfTheCornersKeys) {
  Surface s = surface_of(synthetic::colon(synthetic::colon_options(120, 12, 1.5, {})).mesh);
  std::mt19937 rng(11);
  std::shuffle(s.t.begin(), s.t.end(), rng);
  struct Corner {
    int lo, hi, f, k;
  };
  std::vector<Corner> corners;
  for (int f = 0; f < int(s.t.size()); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = s.t[std::size_t(f)][(k + 1) % 3], b = s.t[std::size_t(f)][(k + 2) % 3];
      corners.push_back({std::min(a, b), std::max(a, b), f, k});
    }
  std::stable_sort(corners.begin(), corners.end(),
                   [](const Corner& x, const Corner& y) { return x.lo != y.lo ? x.lo < y.lo : x.hi < y.hi; });
  Edges ref;
  ref.fe.assign(s.t.size(), {-1, -1, -1});
  for (std::size_t i = 0; i < corners.size(); ++i) {
    const bool same = i > 0 && corners[i].lo == corners[i - 1].lo && corners[i].hi == corners[i - 1].hi;
    if (same) ref.ef.back()[1] = corners[i].f;
    else ref.ev.push_back({corners[i].lo, corners[i].hi}), ref.ef.push_back({corners[i].f, -1});
    ref.fe[std::size_t(corners[i].f)][std::size_t(corners[i].k)] = int(ref.ev.size()) - 1;
  }
  expect_same_edges(build_edges(s.t), ref);
}

// The annulus open_ends returns carries its own edges (both caps cut off a closed colon), and
// opening builds no edge graph: the edges are walked once, on the closed surface.
TEST(FlattenMeshGraph, OpenedAnnulusCarriesItsEdgesWithoutBuildingThem) {
  const Surface s = surface_of(synthetic::colon(synthetic::colon_options(200, 15, 1.2, {})).mesh);
  const Edges E = build_edges(s.t);
  const std::size_t built = build_edges_count();
  const Opened o = open_ends(s, E, 0, 15.0);
  EXPECT_EQ(build_edges_count(), built);
  ASSERT_GT(o.removed, 0u);
  expect_same_edges(o.edges, build_edges(o.annulus.t));
}

// The cap's search (settle_up_to = 30 mm) on a 300 mm tube: every distance up to 30 mm equals the
// full search's bit for bit, every other vertex is above 30 mm or unreached, and most of the tube
// is never reached (below a quarter of its vertices hold a finite value).
TEST(FlattenMeshGraph, BoundedSearchIsExactUpToItsBoundAndStops) {
  const Surface s = surface_of(synthetic::open_cylinder(10, 300, 96, 300));
  const Csr g = build_csr(s, build_edges(s.t));
  const std::vector<double> full = dijkstra(g, {0}), near = dijkstra(g, {0}, 30.0);
  std::size_t reached = 0;
  for (std::size_t v = 0; v < full.size(); ++v) {
    if (full[v] <= 30.0) EXPECT_EQ(near[v], full[v]);
    else EXPECT_GT(near[v], 30.0);
    reached += std::isfinite(near[v]);
  }
  EXPECT_LT(reached, full.size() / 4);
}

// The search as it was written before its indexed heap: std::priority_queue with lazy deletion
// (a vertex pushed again for each shorter distance, stale entries skipped when popped).
std::vector<double> dijkstra_lazy(const Csr& g, const std::vector<int>& sources, double settle_up_to) {
  std::vector<double> d(g.start.size() - 1, kInf);
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> q;
  for (int s : sources) d[s] = 0, q.push({0.0, s});
  while (!q.empty()) {
    auto [dv, v] = q.top();
    q.pop();
    if (dv > d[v]) continue;
    if (dv > settle_up_to) break;
    for (int k = g.start[v]; k < g.start[v + 1]; ++k)
      if (dv + g.len[k] < d[g.nbr[k]]) d[g.nbr[k]] = dv + g.len[k], q.push({d[g.nbr[k]], g.nbr[k]});
  }
  return d;
}

// The indexed-heap search gives the lazy search's distances bit for bit (settled and, beyond a
// bound, unsettled ones) on a closed colon whose vertices are jittered (no two edges alike), from
// one source, from a repeated source and from 40 random sources, unbounded and bounded at 5 and 25 mm.
TEST(FlattenMeshGraph, IndexedHeapSearchGivesTheLazySearchsDistances) {
  Surface s = surface_of(synthetic::colon(synthetic::colon_options(200, 15, 1.2, {})).mesh);
  std::mt19937 rng(3);
  for (V3& p : s.p) p += V3::Random() * 0.2;
  const Csr g = build_csr(s, build_edges(s.t));
  std::vector<int> many;
  for (int k = 0; k < 40; ++k) many.push_back(std::uniform_int_distribution<int>(0, int(s.p.size()) - 1)(rng));
  for (const std::vector<int>& sources : {std::vector<int>{0}, std::vector<int>{7, 7}, many})
    for (double bound : {kInf, 5.0, 25.0}) {
      const std::vector<double> want = dijkstra_lazy(g, sources, bound), got = dijkstra(g, sources, bound);
      ASSERT_EQ(got.size(), want.size());
      EXPECT_EQ(0, std::memcmp(got.data(), want.data(), got.size() * sizeof(double)))
          << sources.size() << " sources, bound " << bound;
    }
}

// The whole-surface clean-up as it was written before clean_face_set (every face and edge of the
// surface walked per round): the reference the face-list version must equal.
std::vector<char> clean_by_mask(const Surface& s, const Edges& E, std::vector<char> keep) {
  for (int iter = 0; iter < 200; ++iter) {
    keep_largest_component(E, keep);
    std::vector<int> bcount(s.p.size(), 0);
    for (std::size_t e = 0; e < E.ev.size(); ++e) {
      const int f0 = E.ef[e][0], f1 = E.ef[e][1];
      if ((f0 >= 0 && keep[f0]) + (f1 >= 0 && keep[f1]) == 1) ++bcount[E.ev[e][0]], ++bcount[E.ev[e][1]];
    }
    bool changed = false;
    for (std::size_t f = 0; f < s.t.size(); ++f) {
      const Tri& t = s.t[f];
      if (!keep[f]) continue;
      const bool all_on = bcount[t[0]] > 0 && bcount[t[1]] > 0 && bcount[t[2]] > 0;
      if (all_on || bcount[t[0]] > 2 || bcount[t[1]] > 2 || bcount[t[2]] > 2) keep[f] = 0, changed = true;
    }
    if (!changed) break;
  }
  return keep;
}

// A branch's faces cleaned from their own list (clean_face_set, walking only them) keep exactly
// the faces the whole-surface clean-up keeps from their mask, on random selections of a closed
// colon (holes, pinch vertices) and on a geodesic patch, whole and with holes; sub_surface of the
// face list is sub_surface of the mask (points, faces, source ids, vertex map). One scratch shared
// by the four selections, each given shuffled with repeats, gives the same faces and is left clean.
TEST(FlattenMeshGraph, FaceSetIsCleanedAsItsMaskIs) {
  const Surface s = surface_of(synthetic::colon(synthetic::colon_options(200, 15, 1.2, {})).mesh);
  const Edges E = build_edges(s.t);
  const std::vector<double> d = dijkstra(build_csr(s, E), {0});
  std::mt19937 rng(11), shuffle_rng(5);
  FaceSetScratch scratch;
  for (double share : {0.9, 0.97, -1.0, -0.9}) {
    std::vector<char> mask(s.t.size());
    for (std::size_t f = 0; f < s.t.size(); ++f)  // share < 0: that share of the faces within 20 mm of vertex 0
      mask[f] = (share > 0 || d[s.t[f][0]] < 20) && std::uniform_real_distribution<double>(0, 1)(rng) < std::abs(share);
    std::vector<int> faces;
    for (std::size_t f = 0; f < s.t.size(); ++f)
      if (mask[f]) faces.push_back(int(f));
    const std::vector<char> want = clean_by_mask(s, E, mask);
    const std::vector<int> got = clean_face_set(s, E, faces);
    std::vector<char> got_mask(s.t.size(), 0);
    for (int f : got) got_mask[f] = 1;
    EXPECT_EQ(got_mask, want) << "share " << share;
    EXPECT_TRUE(std::is_sorted(got.begin(), got.end()));
    std::vector<int> shuffled = faces;
    shuffled.insert(shuffled.end(), faces.begin(), faces.begin() + std::ptrdiff_t(faces.size() / 2));
    std::shuffle(shuffled.begin(), shuffled.end(), shuffle_rng);
    EXPECT_EQ(clean_face_set(s, E, shuffled, &scratch), got) << "share " << share;
    EXPECT_EQ(std::count(scratch.keep.begin(), scratch.keep.end(), 0), std::ptrdiff_t(s.t.size()));
    EXPECT_EQ(std::count(scratch.comp.begin(), scratch.comp.end(), -1), std::ptrdiff_t(s.t.size()));
    EXPECT_EQ(std::count(scratch.bcount.begin(), scratch.bcount.end(), 0), std::ptrdiff_t(s.p.size()));
    ASSERT_GT(got.size(), 0u);
    EXPECT_LT(got.size(), faces.size()) << "share " << share;  // the clean-up removed faces
    std::vector<int> map_mask, map_list;
    const Surface a = sub_surface(s, want, &map_mask), b = sub_surface(s, got, &map_list);
    EXPECT_EQ(a.p, b.p);
    EXPECT_EQ(a.t, b.t);
    EXPECT_EQ(a.src, b.src);
    EXPECT_EQ(map_mask, map_list);
  }
}

}  // namespace
}  // namespace cf
