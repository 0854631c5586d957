// The local area balancing (src/area_balance.cpp) on a tiny flat grid (squeezed_grid.h): a map that
// squeezes the middle of the grid is balanced towards the area bounds, and the balancing ends as
// soon as its steps no longer bring the faces measurably closer to the bounds or lower their angle
// distortion.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>

#include "squeezed_grid.h"
#include "../src/proxy_descent.h"
#include "../src/symmetric_dirichlet_energy.h"

namespace cf::flat_detail {
namespace {

using Grid = test_shapes::SqueezedGrid;

// Squeezed to 0.2 (below area_ratio_low 0.4; the fixed rims leave the squeezed columns little
// room) the grid is balanced: its smallest area ratio rises (so no face folds). Its out-of-bounds and
// angle measures stop falling after ~10 steps while the energy still creeps down: with a step budget of
// 200 the balancing now ends there (it took 35 steps without the stop), and balanced again the
// same map takes at most one step per pass.
TEST(AreaBalance, StopsOnceItsStepsNoLongerGain) {
  FlattenOptions o;
  o.balance_iterations = 200;  // the stop, not the step budget, must end each pass
  Grid g(0.2);
  ASSERT_LT(g.min_ratio(), 0.201);
  const BalanceResult first = balance_area(g.s, g.vf, g.emb, g.fixed, g.degenerate, o);
  EXPECT_GT(first.iterations, 0u);
  EXPECT_LT(first.iterations, 20u);
  EXPECT_GT(g.min_ratio(), 0.22);
  const BalanceResult again = balance_area(g.s, g.vf, g.emb, g.fixed, g.degenerate, o);
  EXPECT_LE(again.iterations, 2u);
  EXPECT_GT(g.min_ratio(), 0.22);
}

// A grid squeezed only mildly (0.6: every face within the bounds) seeds no region: no step.
TEST(AreaBalance, GridWithinBoundsTakesNoStep) {
  FlattenOptions o;
  Grid g(0.6);
  EXPECT_EQ(balance_area(g.s, g.vf, g.emb, g.fixed, g.degenerate, o).iterations, 0u);
}

// A pass whose region is the previous pass's (no step taken in between: balance_iterations 0)
// reuses that region's factorised system: both passes select the squeezed region, one system is
// factorised, and the map does not move.
TEST(AreaBalance, SecondPassOnTheSameRegionReusesItsSystem) {
  FlattenOptions o;
  o.balance_iterations = 0;
  Grid g(0.2);
  const std::vector<V2> before = g.emb.pos;
  const BalanceResult r = balance_area(g.s, g.vf, g.emb, g.fixed, g.degenerate, o);
  EXPECT_GT(r.faces, 0u);
  EXPECT_EQ(r.iterations, 0u);
  EXPECT_EQ(r.systems_built, 1u);
  EXPECT_EQ(g.emb.pos, before);
}

// The region is a list of faces by index whatever seeds it grew from: the whole grid squeezed to ~0.35
// across, unevenly (the seeds nearly every face), one step moves some faces, the second pass's seeds
// differ but grow into the same region (all faces), and it reuses the first pass's system (one
// factorised for the two passes, where a list in growing order, seeds first, made two).
TEST(AreaBalance, RegionGrownFromOtherSeedsReusesItsSystem) {
  FlattenOptions o;
  o.balance_iterations = 1;
  Grid g(1.0);
  for (std::size_t v = 0; v < g.emb.pos.size(); ++v)
    g.emb.pos[v].x() = 0.35 * g.emb.pos[v].x() + (g.fixed[v] ? 0.0 : 0.05 * std::sin(1.7 * double(v)));
  const auto seeds = [&] {
    std::vector<char> seed(g.s.t.size());
    for (std::size_t f = 0; f < seed.size(); ++f) seed[f] = g.emb.area2(g.s, int(f)) < 0.4 * face_area_3d(g.s, int(f));
    return seed;
  };
  const std::vector<char> before = seeds();
  const BalanceResult r = balance_area(g.s, g.vf, g.emb, g.fixed, g.degenerate, o);
  EXPECT_GE(r.iterations, 1u);
  EXPECT_EQ(r.faces, g.s.t.size() - 2);  // all but the two corner faces (no free vertex)
  EXPECT_NE(seeds(), before);  // the step moved faces across a bound
  EXPECT_EQ(r.systems_built, 1u);
}

// The balancing's energy without energy_and_gradients(): proxy_descent asks energy() and
// face_gradients() apart, as before the fused line search.
struct SeparateGradients {
  const SymmetricDirichlet& e;
  static constexpr double kHuge = SymmetricDirichlet::kHuge;
  const std::vector<int>& faces() const { return e.faces(); }
  double energy(const std::vector<V2>& pos) const { return e.energy(pos); }
  void face_gradients(const std::vector<V2>& pos, std::vector<std::array<V2, 3>>& g) const { e.face_gradients(pos, g); }
};

// The symmetric Dirichlet energy's energy_and_gradients() is energy() and face_gradients() to the bit
// (kHuge on a folded map), and the balancing's descent with it takes the same steps as without: same
// count and stop, same map to the bit.
TEST(AreaBalance, FusedSymmetricDirichletGradientsTakeTheSameSteps) {
  Grid fused(0.2), apart(0.2);
  std::vector<int> faces(fused.s.t.size());
  std::vector<double> area3(faces.size());
  std::vector<char> free_vertex(fused.s.p.size());
  for (std::size_t f = 0; f < faces.size(); ++f) faces[f] = int(f), area3[f] = face_area_3d(fused.s, int(f));
  for (std::size_t v = 0; v < free_vertex.size(); ++v) free_vertex[v] = !fused.fixed[v];
  const SymmetricDirichlet e1 = make_energy(fused.s, fused.emb, faces), e2 = make_energy(apart.s, apart.emb, faces);
  std::vector<std::array<V2, 3>> alone(faces.size()), both(faces.size());
  e1.face_gradients(fused.emb.pos, alone);
  EXPECT_EQ(e1.energy_and_gradients(fused.emb.pos, both), e1.energy(fused.emb.pos));
  for (std::size_t i = 0; i < faces.size(); ++i)
    for (int k = 0; k < 3; ++k) ASSERT_EQ(both[i][std::size_t(k)], alone[i][std::size_t(k)]) << i;
  std::vector<V2> folded = fused.emb.pos;
  folded[std::size_t(5 * fused.nx + 12)].x() += 3.0;
  EXPECT_EQ(e1.energy_and_gradients(folded, both), SymmetricDirichlet::kHuge);
  RegionSystem s1, s2;
  const std::vector<std::array<double, 3>> w = corner_weights(fused.s, faces);
  ASSERT_TRUE(s1.build(fused.s, free_vertex, faces, w));
  ASSERT_TRUE(s2.build(apart.s, free_vertex, faces, w));
  static_assert(FusedGradients<SymmetricDirichlet>::value && !FusedGradients<SeparateGradients>::value);
  const DescentResult a = proxy_descent(fused.s, fused.emb, e1, s1, faces, area3, 50, 1e-9);
  const DescentResult b = proxy_descent(apart.s, apart.emb, SeparateGradients{e2}, s2, faces, area3, 50, 1e-9);
  EXPECT_GT(a.steps, 5);
  EXPECT_EQ(a.steps, b.steps);
  EXPECT_STREQ(a.stop, b.stop);
  EXPECT_EQ(fused.emb.pos, apart.emb.pos);
}

// The largest fold-free step reads each face's corners once: it is, to the bit, the smallest of
// face_step_limit() over the faces with a positive area, each with keep = min(0.5, floor x its 3D
// area / its 2D area), for moves that crush some faces and fold others (floor 0 and 0.3).
TEST(AreaBalance, LargestStepIsTheSmallestFaceLimitToTheBit) {
  Grid g(0.2);
  std::vector<V2> next = g.emb.pos;
  for (std::size_t v = 0; v < next.size(); ++v)
    next[v] += V2(0.9 * std::sin(1.7 * double(v)), 0.7 * std::cos(2.3 * double(v)));
  std::vector<int> faces(g.s.t.size());
  std::vector<double> area3(g.s.t.size());
  for (std::size_t f = 0; f < faces.size(); ++f) faces[f] = int(f), area3[f] = face_area_3d(g.s, int(f));
  for (double floor_ratio : {0.0, 0.3}) {
    double smallest = 1.0;
    for (int f : faces)
      if (const double a = g.emb.area2(g.s, f); a > 0)
        smallest = std::min(smallest, face_step_limit(g.s, g.emb, next, f, std::min(0.5, floor_ratio * area3[f] / a)));
    EXPECT_LT(smallest, 1.0);
    EXPECT_EQ(max_area_step(g.s, g.emb, next, faces, area3, floor_ratio), std::max(0.0, smallest));
  }
}

// One triangle with corners c (counter-clockwise) moved by m: face_step_limit()'s inputs.
struct MovedFace {
  Surface s;
  Embedding emb;
  std::vector<V2> next;
  MovedFace(const std::array<V2, 3>& c, const std::array<V2, 3>& m) {
    for (int k = 0; k < 3; ++k) s.p.emplace_back(c[k].x(), c[k].y(), 0.0), emb.pos.push_back(c[k]), next.push_back(c[k] + m[k]);
    s.t.push_back({0, 1, 2});
    emb.dy.push_back({0.0, 0.0, 0.0});
  }
};

// Brute force: the first t in (0, 1] at which the face's doubled area along its move (long double)
// is down to keep x its area now: 20 000 samples, then bisection; -1 when it stays above.
long double first_drop(const MovedFace& f, double keep) {
  const auto area = [&](long double t) {
    long double q[3][2];
    for (int k = 0; k < 3; ++k)
      for (int d = 0; d < 2; ++d) q[k][d] = (long double)f.emb.pos[k][d] + t * ((long double)f.next[k][d] - f.emb.pos[k][d]);
    return (q[1][0] - q[0][0]) * (q[2][1] - q[0][1]) - (q[1][1] - q[0][1]) * (q[2][0] - q[0][0]);
  };
  const long double floor = keep * area(0);
  for (int i = 1; i <= 20000; ++i) {
    long double lo = (i - 1) / 20000.0L, hi = i / 20000.0L;
    if (area(hi) > floor) continue;
    for (int b = 0; b < 80; ++b) (area(0.5L * (lo + hi)) > floor ? lo : hi) = 0.5L * (lo + hi);
    return hi;
  }
  return -1;
}

// face_step_limit() is the first t in (0, 1] at which a face is down to `keep` x its area, or a
// value above 1 when it stays above that up to t = 1 (session 36: such faces skip the root
// formula): against the brute force on 2 000 faces with moves from 1 % to 3 x their size, and on
// a corner moving straight at its opposite edge, reaching it at t = 0.999 / 1.001.
TEST(AreaBalance, FaceLimitIsTheFirstDropWithinTheStepOrAboveOne) {
  std::uint64_t state = 12345;
  const auto uniform = [&] {  // a fixed sequence in [0, 1)
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return double(state >> 11) / 9007199254740992.0;
  };
  int within = 0, beyond = 0;
  for (int i = 0; i < 2000; ++i) {
    std::array<V2, 3> c, m;
    for (int k = 0; k < 3; ++k) c[k] = V2(uniform(), uniform());
    if ((c[1] - c[0]).x() * (c[2] - c[0]).y() - (c[1] - c[0]).y() * (c[2] - c[0]).x() < 1e-3) continue;
    const double size = std::array<double, 4>{0.01, 0.3, 1.0, 3.0}[std::size_t(i % 4)];
    for (int k = 0; k < 3; ++k) m[k] = size * V2(uniform() - 0.5, uniform() - 0.5);
    const MovedFace f(c, m);
    const double keep = i % 3 == 0 ? 0.5 : 0.0;
    const long double want = first_drop(f, keep);
    const double got = face_step_limit(f.s, f.emb, f.next, 0, keep);
    if (want < 0) {
      ++beyond;
      EXPECT_GT(got, 1.0) << i;
    } else {
      ++within;
      EXPECT_NEAR(got, double(want), 1e-9) << i;
    }
  }
  EXPECT_GT(within, 250);
  EXPECT_GT(beyond, 250);
  for (double reach : {0.999, 1.001}) {
    const MovedFace f({V2(0, 0), V2(1, 0), V2(0.3, 1)}, {V2(0, 0), V2(0, 0), V2(0, -1 / reach)});
    const double got = face_step_limit(f.s, f.emb, f.next, 0, 0.0);
    if (reach < 1) EXPECT_NEAR(got, reach, 1e-12);
    else EXPECT_GT(got, 1.0);
  }
}

}  // namespace
}  // namespace cf::flat_detail
