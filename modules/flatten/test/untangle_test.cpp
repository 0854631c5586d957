// Untangling a band's map (src/untangle.cpp) on a tiny flat grid built here: folds inside are
// repaired with the boundary kept, a fold at an end is repaired by sliding the end along itself, and
// a rim that crosses itself gives way (the synthetic pouch tube and the real CTC colon had such folds).
#include <gtest/gtest.h>

#include "colonflat/core/threads.h"
#include "../src/face_blocks.h"
#include "../src/flatten_internal.h"

namespace cf::flat_detail {
namespace {

constexpr int kNx = 12, kNy = 8;  // x = 0 and x = 11 are the band's ends, y = 0 and y = 7 rims
int id(int i, int j) { return j * kNx + i; }

struct Grid {
  Surface s;
  Embedding emb;
  std::vector<char> fixed, degenerate;
  std::vector<std::vector<int>> vf;
};

// A flat nx x ny grid as both the surface (z = 0) and its map (no seam: dy = 0, map period
// `period`), its boundary fixed.
Grid large_grid(int nx, int ny, double period = 1e6) {
  Grid g;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      g.s.p.push_back(V3(i, j, 0));
      g.emb.pos.push_back(V2(i, j));
      g.fixed.push_back(i == 0 || j == 0 || i == nx - 1 || j == ny - 1);
    }
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      const int a = j * nx + i;
      g.s.t.push_back({a, a + 1, a + nx + 1});
      g.s.t.push_back({a, a + nx + 1, a + nx});
    }
  g.emb.dy.assign(g.s.t.size(), {0.0, 0.0, 0.0});
  g.emb.period = period;
  g.degenerate.assign(g.s.t.size(), 0);
  g.vf = vertex_faces(g.s);
  return g;
}

// The kNx x kNy grid (period far larger than the grid).
Grid grid() { return large_grid(kNx, kNy, 1000); }

std::size_t folded_faces(const Grid& g) {
  std::size_t n = 0;
  for (std::size_t f = 0; f < g.s.t.size(); ++f)
    n += too_small_in_map(g.emb.area2(g.s, int(f)), face_area_3d(g.s, int(f)));
  return n;
}

// An interior vertex pushed across its neighbour folds faces; untangling repairs them and leaves
// every boundary vertex where it was.
TEST(Untangle, InteriorFoldWithTheBoundaryKept) {
  Grid g = grid();
  g.emb.pos[id(5, 3)] = V2(7.5, 3.2);
  ASSERT_GT(folded_faces(g), 0u);
  const std::vector<V2> before = g.emb.pos;
  EXPECT_GT(untangle(g.s, g.vf, g.emb, g.fixed, g.degenerate), 0u);
  EXPECT_EQ(folded_faces(g), 0u);
  for (int v = 0; v < kNx * kNy; ++v)
    if (g.fixed[v]) EXPECT_EQ(g.emb.pos[v], before[v]) << v;
}

// Two vertices of an end in the wrong order (what the conformal map did on the pouch tube's end
// loop): the end slides along itself (x stays 0), and no face stays folded.
TEST(Untangle, EndInTheWrongOrderSlidesAlongItself) {
  Grid g = grid();
  g.emb.pos[id(0, 3)] = V2(0, 4.4);
  g.emb.pos[id(0, 4)] = V2(0, 3.6);
  ASSERT_GT(folded_faces(g), 0u);
  untangle(g.s, g.vf, g.emb, g.fixed, g.degenerate);
  EXPECT_EQ(folded_faces(g), 0u);
  for (int j = 0; j < kNy; ++j) {
    EXPECT_EQ(g.emb.pos[id(0, j)].x(), 0.0) << j;
    EXPECT_EQ(g.emb.pos[id(kNx - 1, j)].x(), kNx - 1.0) << j;
  }
}

// A rim vertex pushed past its rim neighbour (the rim of a cut-off branch crossing itself, as on
// the real CTC colon): the rim gives way, no face stays folded, the ends do not move.
TEST(Untangle, RimCrossingItselfGivesWay) {
  Grid g = grid();
  g.emb.pos[id(5, kNy - 1)] = V2(6.6, kNy - 1.3);
  ASSERT_GT(folded_faces(g), 0u);
  untangle(g.s, g.vf, g.emb, g.fixed, g.degenerate);
  EXPECT_EQ(folded_faces(g), 0u);
  for (int j = 0; j < kNy; ++j) {
    EXPECT_EQ(g.emb.pos[id(0, j)], V2(0, j)) << j;
    EXPECT_EQ(g.emb.pos[id(kNx - 1, j)], V2(kNx - 1, j)) << j;
  }
}


// Folds in two blocks of faces far apart (which faces are folded is asked block by block on the
// worker threads): untangled with 1, 2 and 3 threads, the same vertices move to the same bits and
// no fold remains.
TEST(Untangle, FoldsInSeveralBlocksAreRepairedTheSameOnOneTwoThreeThreads) {
  constexpr int nx = 120, ny = 80;
  std::vector<V2> first;
  std::size_t moved_first = 0;
  for (int threads : {1, 2, 3}) {
    Grid g = large_grid(nx, ny);
    ASSERT_GT(g.s.t.size(), 2 * kFaceBlock);
    g.emb.pos[10 * nx + 10] = V2(12.5, 10.2);  // faces of the first block
    g.emb.pos[60 * nx + 100] = V2(100.3, 62.4);  // faces of the second
    ASSERT_GT(folded_faces(g), 0u);
    set_thread_count(threads);
    const std::size_t moved = untangle(g.s, g.vf, g.emb, g.fixed, g.degenerate);
    set_thread_count(0);
    EXPECT_GT(moved, 0u);
    EXPECT_EQ(folded_faces(g), 0u) << threads;
    if (threads == 1) first = g.emb.pos, moved_first = moved;
    EXPECT_EQ(g.emb.pos, first) << threads;
    EXPECT_EQ(moved, moved_first) << threads;
  }
}

// Nothing folded: nothing moves.
TEST(Untangle, UnfoldedMapIsLeftAlone) {
  Grid g = grid();
  const std::vector<V2> before = g.emb.pos;
  EXPECT_EQ(untangle(g.s, g.vf, g.emb, g.fixed, g.degenerate), 0u);
  EXPECT_EQ(g.emb.pos, before);
}

}  // namespace
}  // namespace cf::flat_detail
