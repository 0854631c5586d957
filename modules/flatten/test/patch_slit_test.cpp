// A disk-shaped patch opened along its ridge (src/patch_slit.cpp): the strip of wall a band hides
// becomes an annulus whose second loop runs along the strip's middle, with every face kept.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "../src/branch_bands.h"
#include "../src/patch_slit.h"
#include "colonflat/core/threads.h"
#include "colonflat/flatten/flatten.h"
#include "squeezed_grid.h"
#include "strip_shapes.h"

namespace cf {
namespace {

using flat_detail::V3;

using test_shapes::stadium;
using test_shapes::strip;

// The strip as a TriangleList (flatten_colon's input).
TriangleList as_mesh(const flat_detail::Surface& s) {
  TriangleList m;
  for (const V3& p : s.p) m.points.push_back({p.x(), p.y(), p.z()});
  for (const auto& t : s.t) m.triangles.push_back({t[0], t[1], t[2]});
  return m;
}

// A 61 x 13 mm strip: its slit runs along the middle over the ridge (distance to the rim >= 3 mm:
// x in [3, 57], y in [3, 9]), rounded at both ends (the six faces around each end vertex dropped); the
// cut is an annulus, the slit's inner vertices doubled, every vertex at its source's position.
TEST(PatchSlit, StripIsCutAlongItsMiddleLine) {
  const flat_detail::Surface s = strip(61, 13);
  const flat_detail::Surface cut = flat_detail::slit_disk(s);
  ASSERT_EQ(cut.t.size() + 12, s.t.size());
  const flat_detail::Edges E = flat_detail::build_edges(cut.t);
  const auto loops = flat_detail::boundary_loops(cut, E);
  ASSERT_EQ(loops.size(), 2u);
  EXPECT_EQ((long long)cut.p.size() - (long long)E.ev.size() + (long long)cut.t.size(), 0);
  EXPECT_NEAR(flat_detail::surface_area(cut), 60.0 * 12.0 - 12 * 0.5, 1e-9);
  std::vector<int> uses(s.p.size(), 0);
  for (std::size_t v = 0; v < cut.p.size(); ++v) {
    EXPECT_EQ(cut.p[v], s.p[std::size_t(cut.src[v])]);
    ++uses[std::size_t(cut.src[v])];
  }
  const auto& inner = loops[0].size() < loops[1].size() ? loops[0] : loops[1];
  double xmin = 1e9, xmax = -1e9;
  for (int v : inner) {
    EXPECT_NEAR(cut.p[std::size_t(v)].y(), 6.0, 4.0 + 1e-9);  // on the ridge, or one edge beyond it around an end
    xmin = std::min(xmin, cut.p[std::size_t(v)].x()), xmax = std::max(xmax, cut.p[std::size_t(v)].x());
  }
  EXPECT_LE(xmin, 4.0);  // from near x = 3 ...
  EXPECT_GE(xmax, 56.0);  // ... to near x = 57
  const long long doubled = std::count(uses.begin(), uses.end(), 2), gone = std::count(uses.begin(), uses.end(), 0);
  EXPECT_EQ(gone, 2);  // the two end vertices
  EXPECT_EQ(std::count(uses.begin(), uses.end(), 1) + 2 * doubled, (long long)cut.p.size());
  EXPECT_EQ(inner.size(), std::size_t(2 * doubled + 10));  // both sides of the slit, and 5 + 5 around the ends' fans
}

// A slit one face from the rim would be unzipped into it by the band's boundary clean-up (faces
// with three corners on the boundary dropped one after the other, clean_face_set): on a 61 x 5 mm
// strip (ridge 1 mm from the rim) there is no slit; on a 61 x 7 mm one the slit is cut and the
// clean-up drops no more than it drops of the uncut strip (its corner faces).
TEST(PatchSlit, SlitIsNeverOneFaceFromTheRim) {
  EXPECT_TRUE(flat_detail::slit_disk(strip(61, 5)).t.empty());
  const flat_detail::Surface s = strip(61, 7), cut = flat_detail::slit_disk(s);
  ASSERT_FALSE(cut.t.empty());
  const flat_detail::Edges E = flat_detail::build_edges(cut.t);
  EXPECT_EQ(flat_detail::boundary_loops(cut, E).size(), 2u);
  auto dropped = [](const flat_detail::Surface& x, const flat_detail::Edges& e) {  // faces the clean-up drops
    std::vector<int> all(x.t.size());
    for (std::size_t f = 0; f < all.size(); ++f) all[f] = int(f);
    return x.t.size() - flat_detail::clean_face_set(x, e, all).size();
  };
  EXPECT_EQ(dropped(cut, E), dropped(s, flat_detail::build_edges(s.t)));  // only the strip's own corners
}

// A 3 x 3 grid has one vertex off the rim: its ridge is that vertex, no slit of two edges: no cut.
TEST(PatchSlit, DiskWithOneRidgeVertexIsNotCut) {
  EXPECT_TRUE(flat_detail::slit_disk(strip(3, 3)).t.empty());
}

// A 12 x 120 mm stadium flattened as a band from its rim: from a tip cap at its middle (a pouch's
// map) the harmonic u falls off exponentially along it and its ends are crushed (most of it hidden);
// cut along its slit (a tube from the rim to the slit) nearly all of it is shown, none folded.
TEST(PatchSlit, SlitStripIsShownWhereTheTipCapMapCrushesIt) {
  set_thread_count(1);
  const flat_detail::Surface s = stadium(121);
  FlattenOptions o;
  o.end_cut_radius = 5;  // a branch's tip cap
  o.branch_min_area = 0;  // the strip itself, no branches or patches
  const FlatMap capped = flatten_colon(as_mesh(s), o);
  const FlatMap slit = flatten_colon(as_mesh(flat_detail::slit_disk(s)), o);
  EXPECT_LT(capped.coverage.fraction, 0.5);  // 0.146 measured
  EXPECT_GE(slit.coverage.fraction, 0.99);  // 0.995 measured (the staircase rim's corners)
  EXPECT_EQ(slit.stats.flipped, 0u);
  set_thread_count(0);
}

}  // namespace
}  // namespace cf
