// The sparse pieces of the flatten stage's conformal solve: the edge numbering the Laplacians are
// built from, and the SPD solver with a reused elimination order.
#include <gtest/gtest.h>

#include <future>

#include <algorithm>
#include <numeric>
#include <map>
#include <cmath>
#include <random>
#include <thread>
#include <cstring>
#include <utility>

#include "../src/conformal_factor.h"
#include "../src/factor_schedule.h"
#include "../src/flatten_internal.h"
#include "../src/spd_solver.h"
#include "colonflat/core/error.h"
#include "colonflat/core/threads.h"

namespace {

using cf::flat_detail::SpdSolver;
using cf::flat_detail::Tri;

// An nx x ny grid of vertices, two triangles per cell, faces in a shuffled order.
std::vector<Tri> grid_faces(int nx, int ny, unsigned seed) {
  std::vector<Tri> t;
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      const int a = j * nx + i, b = a + 1, c = a + nx, d = c + 1;
      t.push_back({a, b, d});
      t.push_back({a, d, c});
    }
  std::shuffle(t.begin(), t.end(), std::mt19937(seed));
  return t;
}

// Laplacian of the grid's edges (weight 1 + (lo + hi) % 3) over the vertices with keep[v], plus
// 1 on the diagonal of the first column's vertices (so that it is positive definite).
SpdSolver::SpMat grid_system(const cf::flat_detail::Edges& E, int nx, const std::vector<int>& unknown_of, int n) {
  std::vector<Eigen::Triplet<double>> trip;
  for (const auto& e : E.ev) {
    const int a = unknown_of[e[0]], b = unknown_of[e[1]];
    const double w = 1.0 + (e[0] + e[1]) % 3;
    if (a < 0 || b < 0) continue;
    trip.emplace_back(a, a, w), trip.emplace_back(b, b, w), trip.emplace_back(a, b, -w), trip.emplace_back(b, a, -w);
  }
  for (std::size_t v = 0; v < unknown_of.size(); ++v)
    if (unknown_of[v] >= 0 && int(v) % nx == 0) trip.emplace_back(unknown_of[v], unknown_of[v], 1.0);
  SpdSolver::SpMat A(n, n);
  A.setFromTriplets(trip.begin(), trip.end());
  return A;
}

// grid_system with every vertex its own unknown (vertex v = unknown v), nv = the grid's vertices.
SpdSolver::SpMat whole_grid_system(const cf::flat_detail::Edges& E, int nx, int nv) {
  std::vector<int> all(static_cast<std::size_t>(nv));
  std::iota(all.begin(), all.end(), 0);
  return grid_system(E, nx, all, nv);
}

}  // namespace

// build_edges numbers the edges in (lo, hi) order, as a sort of all corner keys does, with the
// faces on each side (lower face id first) and the edge opposite each face corner.
TEST(FlattenSolver, EdgesAreNumberedInLoHiOrderWithTheirFaces) {
  const std::vector<Tri> t = grid_faces(7, 5, 3);
  const cf::flat_detail::Edges E = cf::flat_detail::build_edges(t);
  std::map<std::pair<int, int>, std::vector<int>> brute;  // (lo, hi) -> faces, increasing
  for (std::size_t f = 0; f < t.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = t[f][(k + 1) % 3], b = t[f][(k + 2) % 3];
      brute[{std::min(a, b), std::max(a, b)}].push_back(int(f));
    }
  ASSERT_EQ(E.ev.size(), brute.size());
  std::size_t e = 0;
  for (const auto& [key, faces] : brute) {
    EXPECT_EQ(E.ev[e][0], key.first);
    EXPECT_EQ(E.ev[e][1], key.second);
    EXPECT_EQ(E.ef[e][0], faces[0]);
    EXPECT_EQ(E.ef[e][1], faces.size() == 2 ? faces[1] : -1);
    ++e;
  }
  for (std::size_t f = 0; f < t.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      const auto& ev = E.ev[E.fe[f][k]];
      const int a = t[f][(k + 1) % 3], b = t[f][(k + 2) % 3];
      EXPECT_EQ(ev[0], std::min(a, b));
      EXPECT_EQ(ev[1], std::max(a, b));
    }
  std::vector<Tri> fan = {{0, 1, 2}, {0, 2, 1}, {0, 1, 3}};  // edge (0, 1) in three faces
  EXPECT_THROW(cf::flat_detail::build_edges(fan), cf::PreconditionError);
}

// A system on a subgraph solved with the elimination order of the whole graph, restricted to the
// subgraph's vertices, has the same solution as with its own AMD order; the orders reported are
// permutations of the unknowns (empty only without CHOLMOD).
TEST(FlattenSolver, RestrictedOrderOfALargerGraphSolvesTheSubgraph) {
  const int nx = 40, ny = 25, nv = nx * ny;
  const auto E = cf::flat_detail::build_edges(grid_faces(nx, ny, 5));
  std::vector<int> all(nv);
  for (int v = 0; v < nv; ++v) all[v] = v;
  SpdSolver whole;
  ASSERT_TRUE(whole.compute(grid_system(E, nx, all, nv)));
  const std::vector<int> order = whole.order();
  if (!order.empty()) {
    std::vector<int> sorted = order;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(sorted, all);
  }
  std::vector<int> unknown_of(nv, -1), restricted;  // the subgraph: a 10 x 8 block removed
  int n = 0;
  for (int v = 0; v < nv; ++v)
    if (!(v % nx >= 20 && v % nx < 30 && v / nx >= 5 && v / nx < 13)) unknown_of[v] = n++;
  for (int v : order)
    if (unknown_of[v] >= 0) restricted.push_back(unknown_of[v]);
  const SpdSolver::SpMat A = grid_system(E, nx, unknown_of, n);
  Eigen::VectorXd b(n);
  for (int i = 0; i < n; ++i) b[i] = std::sin(0.37 * i) + 0.1;
  SpdSolver amd, reused;
  ASSERT_TRUE(amd.compute(A));
  ASSERT_TRUE(reused.compute(A, order.empty() ? nullptr : &restricted));
  const Eigen::VectorXd x_amd = amd.solve(b), x_reused = reused.solve(b);
  EXPECT_LT((A * x_reused - b).norm(), 1e-10 * b.norm());
  EXPECT_LT((x_reused - x_amd).norm(), 1e-10 * x_amd.norm());
  if (!order.empty()) {  // CHOLMOD may postorder the given order: still a permutation of the unknowns
    std::vector<int> used = reused.order(), expected(n);
    std::sort(used.begin(), used.end());
    for (int i = 0; i < n; ++i) expected[i] = i;
    EXPECT_EQ(used, expected);
  }
}

// One factorisation of a system with some unknowns ordered last also solves the system on the
// others with those held at 0 (its leading block, as the conformal map solves u with v's factor):
// the same solution as a factorisation of that block alone; without a given order it is refused.
TEST(FlattenSolver, LeadingBlockOfTheOrderSolvesTheSystemWithTheRestHeldAtZero) {
  const int nx = 30, ny = 20, nv = nx * ny;
  const auto E = cf::flat_detail::build_edges(grid_faces(nx, ny, 7));
  const SpdSolver::SpMat A = whole_grid_system(E, nx, nv);
  auto held = [&](int v) { return v % nx == nx - 1 || v / nx == 0; };  // last column and first row
  std::vector<int> order, unknown_of(nv, -1);  // AMD's order with the held unknowns moved last
  const std::vector<int> amd = SpdSolver::fill_reducing_order(A);
  ASSERT_EQ(amd.size(), std::size_t(nv));
  int leading = 0;
  for (int pass = 0; pass < 2; ++pass)
    for (int v : amd)
      if (held(v) == (pass == 1)) order.push_back(v), leading += pass == 0;
  for (int v = 0, n = 0; v < nv; ++v)
    if (!held(v)) unknown_of[v] = n++;
  Eigen::VectorXd b(nv), b_inner(leading);
  for (int v = 0; v < nv; ++v) {
    b[v] = held(v) ? 1e3 : std::cos(0.21 * v) + 0.3;  // the held entries must not be read
    if (!held(v)) b_inner[unknown_of[v]] = b[v];
  }
  std::vector<Eigen::Triplet<double>> block;  // A's principal submatrix on the unknowns not held
  for (int j = 0; j < A.outerSize(); ++j)
    for (SpdSolver::SpMat::InnerIterator it(A, j); it; ++it)
      if (unknown_of[it.row()] >= 0 && unknown_of[j] >= 0) block.emplace_back(unknown_of[it.row()], unknown_of[j], it.value());
  SpdSolver::SpMat A_inner(leading, leading);
  A_inner.setFromTriplets(block.begin(), block.end());
  SpdSolver one, inner, unordered;
  ASSERT_TRUE(one.compute(A, &order));
  ASSERT_TRUE(inner.compute(A_inner));
  const Eigen::VectorXd x = one.solve_leading(b, leading), x_inner = inner.solve(b_inner);
  for (int v = 0; v < nv; ++v) {
    if (held(v)) EXPECT_EQ(x[v], 0.0);
    else EXPECT_NEAR(x[v], x_inner[unknown_of[v]], 1e-10 * x_inner.norm());
  }
  ASSERT_TRUE(unordered.compute(A));
  EXPECT_THROW(unordered.solve_leading(b, leading), cf::Error);
}

namespace {

// An open tube of nz rings of na vertices (radius varying along it and around it, so that the
// cotangent weights differ), two triangles per cell; vertex j * na + i.
cf::flat_detail::Surface bumpy_tube(int na, int nz) {
  cf::flat_detail::Surface s;
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < na; ++i) {
      const double a = 2 * M_PI * i / na, r = 10 + 2 * std::sin(0.3 * j) + std::cos(3 * a);
      s.p.emplace_back(r * std::cos(a), r * std::sin(a), 1.3 * j + 0.2 * std::sin(a));
      s.src.push_back(int(s.p.size()) - 1);
    }
  for (int j = 0; j + 1 < nz; ++j)
    for (int i = 0; i < na; ++i) {
      const int a = j * na + i, b = j * na + (i + 1) % na, c = a + na, d = b + na;
      s.t.push_back({a, b, d});
      s.t.push_back({a, d, c});
    }
  return s;
}

}  // namespace

// An end loop holding a vertex that is not the surface's (-1, or one past its last) is refused with
// one error before anything is written (it would index outside the band's arrays); the loops
// themselves solve.
TEST(FlattenSolver, EndLoopWithAVertexOutsideTheBandIsRefused) {
  using namespace cf::flat_detail;
  const Surface tube = bumpy_tube(12, 20);
  const Edges E = build_edges(tube.t);
  const auto loops = boundary_loops(tube, E);
  ASSERT_EQ(loops.size(), 2u);
  EXPECT_GT(solve_harmonic(tube, E, loops[0], loops[1], false).period, 0);
  for (int bad : {-1, int(tube.p.size())}) {
    std::vector<int> a = loops[0];
    a.push_back(bad);
    try {
      solve_harmonic(tube, E, a, loops[1], false);
      ADD_FAILURE() << "vertex " << bad << " was accepted";
    } catch (const cf::Error& e) {
      EXPECT_NE(std::string(e.what()).find("not the band's"), std::string::npos) << e.what();
    }
  }
}

// The map after cutting pieces out of a surface, solved by updating the first map's factorisation
// (rank-one terms for the changed weights, the cut-off vertices grounded), equals a new solve on
// what remains; two cut-off pieces (two holes) are each grounded.
TEST(FlattenSolver, UpdatedFactorisationSolvesTheSurfaceThatRemains) {
  using namespace cf::flat_detail;
  const int na = 24, nz = 400;  // long: the update costs far less than a new factorisation
  const Surface whole = bumpy_tube(na, nz);
  const Edges E0 = build_edges(whole.t);
  auto loops = boundary_loops(whole, E0);
  ASSERT_EQ(loops.size(), 2u);
  if (loops[0][0] != 0) std::swap(loops[0], loops[1]);
  PriorSolve prior;
  Harmonic first = solve_harmonic(whole, E0, loops[0], loops[1], false, &prior);
  ASSERT_TRUE(first.factor);
  std::vector<char> keep(whole.t.size(), 1);
  for (std::size_t f = 0; f < whole.t.size(); ++f) {
    const int j = whole.t[f][0] / na, i = whole.t[f][0] % na;
    if ((j >= 10 && j < 15 && i >= 3 && i < 8) || (j >= 25 && j < 28 && i >= 12 && i < 20)) keep[f] = 0;
  }
  std::vector<int> new_of_old;
  const Surface rest = sub_surface(whole, keep, &new_of_old);
  const Edges E1 = build_edges(rest.t);
  ASSERT_EQ(boundary_loops(rest, E1).size(), 4u);  // two ends, two holes
  for (auto& l : loops)
    for (int& v : l) v = new_of_old[v];
  prior = PriorSolve{{}, std::move(first.factor), new_of_old};
  for (int v : first.vertex_order)
    if (new_of_old[v] >= 0) prior.vertex_order.push_back(new_of_old[v]);
  const Harmonic updated = solve_harmonic(rest, E1, loops[0], loops[1], false, &prior);
  const Harmonic fresh = solve_harmonic(rest, E1, loops[0], loops[1], false);
  EXPECT_FALSE(updated.factor);  // the update was used, not a new factorisation
  ASSERT_TRUE(fresh.factor);
  EXPECT_LT((updated.u - fresh.u).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_LT((updated.v - fresh.v).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_NEAR(updated.period, fresh.period, 1e-10 * fresh.period);
  double moved = 0;  // the holes change the map: the test compares something that moved
  for (std::size_t v = 0; v < whole.p.size(); ++v)
    if (new_of_old[v] >= 0) moved = std::max(moved, std::abs(first.v[Eigen::Index(v)] - fresh.v[new_of_old[v]]));
  EXPECT_GT(moved, 1e-3);
}

// The update-or-refactorise rule on the stress rows' measured numbers (estimated update flops,
// first factorisation's flops; session 31): updates where the update took 0.05-0.54 of a new
// factorisation's wall time (real CT, CT mask and its raw row, the real mask's bands), new
// factorisations where it took 1.07-3.4 (the generated U's, the grown masks), and the CT mask row
// accepted with room (the four-part order's 3.44e9 against 10 % fewer flops).
TEST(FlattenSolver, FactorUpdateIsChosenWhereItWasMeasuredCheaper) {
  using cf::flat_detail::update_is_cheaper;
  EXPECT_TRUE(update_is_cheaper(2.76e9, 7.05e9));        // real CT: 0.14
  EXPECT_TRUE(update_is_cheaper(3.44e9, 6.88e9 * 0.9));  // CT mask, four-part order, 10 % fewer flops
  EXPECT_TRUE(update_is_cheaper(5.00e9, 6.80e9));        // CT mask raw: 0.54
  EXPECT_TRUE(update_is_cheaper(7.92e8, 8.38e8));        // real mask, 80 k-unknown band: 0.44
  EXPECT_FALSE(update_is_cheaper(8.08e9, 6.37e9));       // U60: 1.42
  EXPECT_FALSE(update_is_cheaper(5.52e9, 3.67e9));       // real mask grown: 1.31
  EXPECT_FALSE(update_is_cheaper(1.52e10, 8.31e9));      // U120: 1.07
  EXPECT_FALSE(update_is_cheaper(1.0, 0.0));             // no factorisation to compare with
}

// A first solve whose elimination order is still being computed on another thread (as beside the
// opening of a colon's ends) asks for it once, when its system is assembled, and gives the map of
// that order given up front to the bit (nested dissection's order, not AMD's).
TEST(FlattenSolver, OrderStillBeingComputedGivesTheMapOfTheOrderGivenUpFront) {
  using namespace cf::flat_detail;
  const Surface tube = bumpy_tube(24, 400);
  const Edges E = build_edges(tube.t);
  auto loops = boundary_loops(tube, E);
  ASSERT_EQ(loops.size(), 2u);
  if (loops[0][0] != 0) std::swap(loops[0], loops[1]);
  const int nv = int(tube.p.size());
  auto computing = std::async(std::launch::async, [&tube, nv] { return nested_dissection_vertex_order(tube.t, nv); }).share();
  int asked = 0;
  PriorSolve pending;
  pending.order_when_ready = [&] {
    ++asked;
    return computing.get();
  };
  const Harmonic late = solve_harmonic(tube, E, loops[0], loops[1], false, &pending);
  PriorSolve given;
  given.vertex_order = computing.get();
  const Harmonic early = solve_harmonic(tube, E, loops[0], loops[1], false, &given);
  const Harmonic amd = solve_harmonic(tube, E, loops[0], loops[1], false);
  EXPECT_EQ(asked, 1);
  EXPECT_FALSE(pending.order_when_ready);
  EXPECT_EQ(late.vertex_order, early.vertex_order);
  EXPECT_NE(late.vertex_order, amd.vertex_order);
  int differ = 0;
  for (Eigen::Index v = 0; v < Eigen::Index(nv); ++v) differ += late.u[v] != early.u[v] || late.v[v] != early.v[v];
  EXPECT_EQ(differ, 0);
  EXPECT_EQ(late.period, early.period);
}

// The nested dissection order (METIS) of a large grid is a permutation of its unknowns whose
// factorisation solves the system as exactly as AMD's does, with fewer operations (the reason large
// colon bands use it after their first map).
TEST(FlattenSolver, NestedDissectionOrderSolvesWithFewerOperationsThanAmd) {
  const int nx = 250, nv = nx * nx;
  const auto E = cf::flat_detail::build_edges(grid_faces(nx, nx, 13));
  std::vector<int> all(nv);
  for (int v = 0; v < nv; ++v) all[v] = v;
  const SpdSolver::SpMat A = grid_system(E, nx, all, nv);
  std::vector<int> order = SpdSolver::nested_dissection_order(A);
  std::vector<int> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  ASSERT_EQ(sorted, all);
  SpdSolver nd, amd;
  ASSERT_TRUE(nd.compute(A, &order));
  ASSERT_TRUE(amd.compute(A));
  Eigen::VectorXd b(nv);
  for (int i = 0; i < nv; ++i) b[i] = std::sin(0.011 * i) + 0.2;
  const SpdSolver::SpMat full = A.selfadjointView<Eigen::Lower>();
  const double amd_residual = (full * amd.solve(b) - b).norm();
  EXPECT_LT((full * nd.solve(b) - b).norm(), std::max(10 * amd_residual, 1e-12 * b.norm()));
  if (amd.factor_flops() > 0) EXPECT_LT(nd.factor_flops(), 0.9 * amd.factor_flops());
}

// A segment with kNestedDissectionMinVertices vertices flattened area-balanced gets nested
// dissection's order already for its first conformal solve (fewer factorisation operations than
// AMD's, which it got before); one vertex fewer, or the conformal map alone, keeps AMD's.
TEST(FlattenSolver, LargeSegmentsFirstSolveIsInNestedDissectionOrder) {
  const int nx = 448, nv = nx * nx;  // 200 704 vertices
  const auto big = std::size_t(nv);
  ASSERT_GE(big, cf::flat_detail::kNestedDissectionMinVertices);
  const std::vector<Tri> faces = grid_faces(nx, nx, 19);
  const auto E = cf::flat_detail::build_edges(faces);
  const std::size_t limit = cf::flat_detail::kNestedDissectionMinVertices;
  EXPECT_TRUE(cf::flat_detail::uses_dissection(limit, "area-balanced"));
  EXPECT_FALSE(cf::flat_detail::uses_dissection(limit - 1, "area-balanced"));
  EXPECT_FALSE(cf::flat_detail::uses_dissection(big, "conformal"));
  const std::vector<int> order = cf::flat_detail::nested_dissection_vertex_order(faces, nv);
  EXPECT_EQ(cf::flat_detail::small_segment_vertex_order(E, nv).order, cf::flat_detail::fill_reducing_vertex_order(E, nv));
  const SpdSolver::SpMat A = whole_grid_system(E, nx, nv);
  SpdSolver first, amd;
  first.analyze(A, &order);
  amd.analyze(A);
  if (amd.factor_flops() > 0) EXPECT_LT(first.factor_flops(), 0.9 * amd.factor_flops());
}

namespace {

// The faces of an open tube of nz rings of na vertices (vertex j * na + i), two triangles per cell.
std::vector<Tri> tube_faces(int na, int nz) {
  std::vector<Tri> t;
  for (int j = 0; j + 1 < nz; ++j)
    for (int i = 0; i < na; ++i) {
      const int a = j * na + i, b = j * na + (i + 1) % na, c = a + na, d = b + na;
      t.push_back({a, b, d});
      t.push_back({a, d, c});
    }
  return t;
}

// The factorisation of the tube's graph Laplacian (+1 on the diagonal of the first ring) in `order`
// (analysed only): its operations and its dense root.
struct OrderCost {
  double flops = 0;
  int root = 0;
};
OrderCost order_cost(const cf::flat_detail::Edges& E, int na, int nv, const std::vector<int>& order) {
  SpdSolver s;
  s.analyze(whole_grid_system(E, na, nv), &order);
  return {s.factor_flops(), s.dense_root_columns()};
}

}  // namespace

// A long tube below kNestedDissectionMinVertices (a long side branch): AMD's order ends in a dense
// root of more than two rings and costs more than kDissectionMinFlopsPerVertex operations per
// vertex, and the segment gets nested dissection's order instead: its dense root is one cut across
// the tube (at most two rings, 2 na) and it needs at most 0.6 of AMD's operations. A short, wide
// tube of the same circumference keeps AMD's order.
TEST(FlattenSolver, LongTubeWhoseAmdOrderHasADenseRootGetsNestedDissection) {
  using namespace cf::flat_detail;
  const int na = 160, nz = 600, nv = na * nz;  // 96 000 vertices
  ASSERT_LT(std::size_t(nv), kNestedDissectionMinVertices);
  const Edges E = build_edges(tube_faces(na, nz));
  const SegmentOrder chosen = small_segment_vertex_order(E, nv, true);
  const OrderCost amd = order_cost(E, na, nv, fill_reducing_vertex_order(E, nv));
  if (amd.flops == 0) GTEST_SKIP() << "no CHOLMOD: no operation counts";
  const OrderCost got = order_cost(E, na, nv, chosen.order);
  EXPECT_GT(amd.flops / nv, kDissectionMinFlopsPerVertex);
  EXPECT_GT(amd.root, 2 * na);
  EXPECT_TRUE(chosen.nested);
  EXPECT_LE(got.root, 2 * na);
  EXPECT_LT(got.flops, 0.6 * amd.flops);
  const int short_nz = 60, short_nv = na * short_nz;  // a short, wide tube: AMD's order is kept
  const Edges Es = build_edges(tube_faces(na, short_nz));
  const SegmentOrder kept = small_segment_vertex_order(Es, short_nv, true);
  EXPECT_LT(order_cost(Es, na, short_nv, kept.order).flops / short_nv, kDissectionMinFlopsPerVertex);
  EXPECT_FALSE(kept.nested);
  EXPECT_EQ(kept.order, fill_reducing_vertex_order(Es, short_nv));
}

// Two nested dissection orders computed at the same time (two large colon segments flattened side
// by side) are each the order computed alone: METIS draws from the C library's one rand() state, so
// its calls must not overlap (they did before: the orders then depended on the timing).
TEST(FlattenSolver, NestedDissectionOrdersAtTheSameTimeAreEachTheOrderAlone) {
  std::vector<SpdSolver::SpMat> systems;
  for (int nx : {200, 210}) {
    const auto E = cf::flat_detail::build_edges(grid_faces(nx, nx, 23));
    systems.push_back(whole_grid_system(E, nx, nx * nx));
  }
  const std::vector<int> alone0 = SpdSolver::nested_dissection_order(systems[0]);
  const std::vector<int> alone1 = SpdSolver::nested_dissection_order(systems[1]);
  for (int round = 0; round < 3; ++round) {
    std::vector<int> at_once0, at_once1;
    std::thread other([&] { at_once1 = SpdSolver::nested_dissection_order(systems[1]); });
    at_once0 = SpdSolver::nested_dissection_order(systems[0]);
    other.join();
    EXPECT_EQ(at_once0, alone0) << "round " << round;
    EXPECT_EQ(at_once1, alone1) << "round " << round;
  }
}

namespace {

// The system of a 150 x 150 grid (22 500 unknowns: above the threaded factorisation's threshold)
// and cholmod_metis's one-call nested dissection order (the order these schedule tests were written
// on: its top separators leave four balanced quarters; the split order of this grid needs one phase).
struct NestedGrid {
  SpdSolver::SpMat A;
  std::vector<int> order;
};
NestedGrid nested_grid() {
  const int nx = 150, nv = nx * nx;
  const auto E = cf::flat_detail::build_edges(grid_faces(nx, nx, 17));
  NestedGrid g{whole_grid_system(E, nx, nv), {}};
  g.order = SpdSolver::one_call_dissection_order(g.A);
  if (g.order.empty()) g.order = SpdSolver::nested_dissection_order(g.A);
  return g;
}

// triu(P A P^T) of the grid's system, P its nested dissection order (what the factorisation reads).
SpdSolver::SpMat permuted_upper(const NestedGrid& g) {
  const int n = int(g.A.rows());
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> place(n);  // unknown -> its place
  for (int k = 0; k < n; ++k) place.indices()[g.order[std::size_t(k)]] = k;
  SpdSolver::SpMat permuted, upper;
  permuted = g.A.selfadjointView<Eigen::Lower>().twistedBy(place);
  upper = permuted.triangularView<Eigen::Upper>();
  upper.makeCompressed();
  return upper;
}

// The grid's factor as the row schedule reads it: triu(P A P^T), its elimination tree and each row's work.
struct GridRows {
  int n = 0;
  SpdSolver::SpMat upper;
  std::vector<int> parent;
  std::vector<double> work;
};
GridRows grid_rows(const NestedGrid& g) {
  GridRows r;
  r.n = int(g.A.rows());
  r.upper = permuted_upper(g);
  r.parent = cf::flat_detail::elimination_tree(r.n, r.upper.outerIndexPtr(), r.upper.innerIndexPtr());
  r.work = cf::flat_detail::row_work(r.n, r.upper.outerIndexPtr(), r.upper.innerIndexPtr(), r.parent);
  return r;
}

}  // namespace

// The rows of a nested dissection factor split into two parts of whole elimination subtrees (each
// row's parent in its own part or above both, every row once) that are about even, with little
// left above them: the split the threaded factorisation computes side by side.
TEST(FlattenSolver, RowScheduleSplitsTheEliminationTreeIntoIndependentEvenParts) {
  const GridRows r = grid_rows(nested_grid());
  const int n = r.n;
  const std::vector<int>& parent = r.parent;
  const cf::flat_detail::RowSchedule s = cf::flat_detail::schedule_rows(parent, std::vector<double>(n, 1.0), 2);
  ASSERT_EQ(s.parts.size(), 2u);
  std::vector<int> where(n, -2);  // part of each row, -1: the rest
  for (int p = 0; p < 2; ++p)
    for (int k : s.parts[p]) EXPECT_EQ(std::exchange(where[k], p), -2) << "row " << k << " twice";
  for (int k : s.rest) EXPECT_EQ(std::exchange(where[k], -1), -2) << "row " << k << " twice";
  for (int k = 0; k < n; ++k) {
    ASSERT_NE(where[k], -2) << "row " << k << " in no part";
    if (parent[k] < 0) continue;
    if (where[k] >= 0) {
      EXPECT_TRUE(where[parent[k]] == where[k] || where[parent[k]] == -1) << k;
    } else {
      EXPECT_EQ(where[parent[k]], -1) << k;
    }
  }
  EXPECT_DOUBLE_EQ(s.total_work, double(n));
  EXPECT_LT(s.largest_part, 0.6 * n);
  EXPECT_LT(s.rest_work, 0.05 * n);
}

// row_work is the up-looking kernel's cost of each row as counted on the factor itself (Eigen's
// LDL^T of the permuted grid system: the m-th entry below the diagonal of a column costs m, m - 1
// updates and the entry), so the split's estimated rest is the rest rows' real share of the work;
// with the old estimate (a column's squared count at its own row) the rest came out several times
// too small.
TEST(FlattenSolver, RowWorkIsTheUpLookingKernelsCostOfEachRow) {
  const GridRows r = grid_rows(nested_grid());
  const int n = r.n;
  const std::vector<int>& parent = r.parent;
  const std::vector<double>& work = r.work;
  const SpdSolver::SpMat lower = r.upper.transpose();
  Eigen::SimplicialLDLT<SpdSolver::SpMat, Eigen::Lower, Eigen::NaturalOrdering<int>> ldlt(lower);
  ASSERT_EQ(ldlt.info(), Eigen::Success);
  const SpdSolver::SpMat L = ldlt.matrixL();
  std::vector<double> cost(std::size_t(n), 1.0);  // the diagonal
  for (int j = 0; j < n; ++j) {
    int m = 0;
    for (SpdSolver::SpMat::InnerIterator it(L, j); it; ++it)
      if (it.row() > j) cost[std::size_t(it.row())] += 1.0 + m++;
  }
  ASSERT_EQ(work.size(), cost.size());
  for (int k = 0; k < n; ++k) ASSERT_EQ(work[std::size_t(k)], cost[std::size_t(k)]) << "row " << k;
  const cf::flat_detail::RowSchedule s = cf::flat_detail::schedule_rows(parent, work, 2);
  double rest = 0, total = 0;
  for (int k : s.rest) rest += cost[std::size_t(k)];
  for (double c : cost) total += c;
  EXPECT_NEAR(s.rest_work / s.total_work, rest / total, 1e-12);
  EXPECT_LT(s.largest_part + s.rest_work, 0.75 * s.total_work);  // two threads still gain a quarter
}

// The rows above the parts split again in phases (four parts of the grid: the first phase leaves the
// top separator and the two below it, which the second runs side by side): every row in one place,
// each row's parent in its own part of its own phase or in a later phase (so a phase's parts only
// read finished rows and their own), and the estimated time with four threads (each phase's largest
// part, then the last rest) below the one-phase split's.
TEST(FlattenSolver, RowPhasesSplitTheRestAgainIntoIndependentParts) {
  const GridRows r = grid_rows(nested_grid());
  const int n = r.n;
  const std::vector<int>& parent = r.parent;
  const std::vector<double>& work = r.work;
  const auto phases = cf::flat_detail::schedule_phases(parent, work, 4);
  const int last = int(phases.size());
  std::vector<std::pair<int, int>> where(std::size_t(n), {-1, -1});  // (phase, part); (last, -1): the rest
  double time = 0;
  for (int i = 0; i < last; ++i) {
    time += phases[std::size_t(i)].largest_part;
    for (int p = 0; p < 4; ++p)
      for (int k : phases[std::size_t(i)].parts[std::size_t(p)]) EXPECT_EQ(std::exchange(where[std::size_t(k)], {i, p}).first, -1);
    if (i + 1 < last) EXPECT_TRUE(phases[std::size_t(i)].rest.empty());
  }
  for (int k : phases.back().rest) EXPECT_EQ(std::exchange(where[std::size_t(k)], {last, -1}).first, -1);
  for (int k = 0; k < n; ++k) {
    ASSERT_NE(where[std::size_t(k)].first, -1) << "row " << k << " in no phase";
    if (parent[std::size_t(k)] < 0) continue;
    const auto up = where[std::size_t(parent[std::size_t(k)])];
    EXPECT_TRUE(up.first > where[std::size_t(k)].first || up == where[std::size_t(k)]) << "row " << k;
  }
  time += phases.back().rest_work;
  const cf::flat_detail::RowSchedule one = cf::flat_detail::schedule_rows(parent, work, 4);
  EXPECT_GT(last, 1);
  EXPECT_LT(time, one.largest_part + one.rest_work);
}

// split_rest_work divides the rest's estimated work by the column each update reads, as counted on
// the factor itself (Eigen's LDL^T of the permuted grid system: the m-th entry below the diagonal of
// column j, at row i, costs 1 + m at row i): the updates of rest rows with the columns of rows in
// the parts, and the rest's own (its columns and diagonals); the two add up to the rest's work.
TEST(FlattenSolver, RestWorkSplitsIntoTheUpdatesFromThePartsColumnsAndItsOwn) {
  const GridRows r = grid_rows(nested_grid());
  const cf::flat_detail::RowSchedule s = cf::flat_detail::schedule_rows(r.parent, r.work, 2);
  ASSERT_FALSE(s.rest.empty());
  std::vector<char> in_rest(std::size_t(r.n), 0);
  for (int k : s.rest) in_rest[std::size_t(k)] = 1;
  const SpdSolver::SpMat lower = r.upper.transpose();
  Eigen::SimplicialLDLT<SpdSolver::SpMat, Eigen::Lower, Eigen::NaturalOrdering<int>> ldlt(lower);
  ASSERT_EQ(ldlt.info(), Eigen::Success);
  const SpdSolver::SpMat L = ldlt.matrixL();
  double from_parts = 0, own = double(s.rest.size());  // (the rest's diagonals)
  for (int j = 0; j < r.n; ++j) {
    int m = 0;
    for (SpdSolver::SpMat::InnerIterator it(L, j); it; ++it)
      if (it.row() > j) {
        const double cost = 1.0 + m++;
        if (in_rest[std::size_t(it.row())]) (in_rest[std::size_t(j)] ? own : from_parts) += cost;
      }
  }
  const cf::flat_detail::RestWork got =
      cf::flat_detail::split_rest_work(r.n, r.upper.outerIndexPtr(), r.upper.innerIndexPtr(), r.parent, s.rest);
  EXPECT_EQ(got.from_parts, from_parts);
  EXPECT_EQ(got.own, own);
  EXPECT_GT(got.from_parts, 0.0);
  EXPECT_DOUBLE_EQ(got.from_parts + got.own, s.rest_work);
}

// The factorisation with its rows on two threads and on four (the same two parts: the schedule is of
// kFactorParts parts for any thread count) is bit for bit the one-thread one (the parts one after
// the other): the same solution to the last bit, and it solves the system.
TEST(FlattenSolver, FactorisationOnTwoThreadsIsBitwiseTheSequentialOne) {
  const NestedGrid g = nested_grid();
  const int n = int(g.A.rows());
  Eigen::MatrixXd b(n, 2);
  for (int i = 0; i < n; ++i) b(i, 0) = std::sin(0.013 * i) + 0.3, b(i, 1) = std::cos(0.007 * i);
  Eigen::MatrixXd x[3];
  for (int threads : {1, 2, 4}) {
    cf::set_thread_count(threads);
    SpdSolver solver;
    ASSERT_TRUE(solver.compute(g.A, &g.order));
    x[threads / 2] = solver.solve(b);
  }
  cf::set_thread_count(0);
  const SpdSolver::SpMat full = g.A.selfadjointView<Eigen::Lower>();
  EXPECT_LT((full * x[1] - b).norm(), 1e-9 * b.norm());
  for (int i : {1, 2}) EXPECT_EQ(std::memcmp(x[0].data(), x[i].data(), sizeof(double) * std::size_t(x[0].size())), 0) << i;
}

// A factorisation in a given order on two threads splits its rows by the schedule computed beside
// its symbolic analysis (analyze() runs both at once), and its solution is the one-thread one (its
// schedule computed after the analysis) to the last bit; without a given order (AMD, known only after the analysis)
// the schedule is computed afterwards, as before.
TEST(FlattenSolver, RowScheduleComputedBesideTheAnalysisGivesTheSequentialFactor) {
  const NestedGrid g = nested_grid();
  const int n = int(g.A.rows());
  Eigen::MatrixXd b(n, 1);
  for (int i = 0; i < n; ++i) b(i, 0) = std::sin(0.011 * i) + 0.2;
  Eigen::MatrixXd x[2];
  for (int threads : {1, 2}) {
    cf::set_thread_count(threads);
    SpdSolver solver;
    solver.analyze(g.A, &g.order);
    ASSERT_TRUE(solver.factorize(g.A));
    if (!solver.order().empty()) EXPECT_EQ(solver.early_schedule(), threads == 2);  // (with CHOLMOD)
    x[threads - 1] = solver.solve(b);
  }
  SpdSolver amd;
  cf::set_thread_count(2);
  ASSERT_TRUE(amd.compute(g.A));
  EXPECT_FALSE(amd.early_schedule());
  cf::set_thread_count(0);
  const SpdSolver::SpMat full = g.A.selfadjointView<Eigen::Lower>();
  EXPECT_LT((full * x[1] - b).norm(), 1e-9 * b.norm());
  EXPECT_EQ(std::memcmp(x[0].data(), x[1].data(), sizeof(double) * std::size_t(n)), 0);
}

#ifdef COLONFLAT_HAVE_CHOLMOD
namespace {

// The largest |difference| of two simplicial factors' values, or -1 when their patterns differ;
// `bitwise`: whether every column's row indices and values are the same bytes.
double factor_difference(const cholmod_factor* a, const cholmod_factor* b, bool& bitwise) {
  bitwise = a->n == b->n;
  if (!bitwise) return -1;
  const int *ap = static_cast<const int*>(a->p), *bp = static_cast<const int*>(b->p);
  const int *anz = static_cast<const int*>(a->nz), *bnz = static_cast<const int*>(b->nz);
  const double *ax = static_cast<const double*>(a->x), *bx = static_cast<const double*>(b->x);
  double most = 0;
  for (std::size_t j = 0; j < a->n; ++j) {
    const std::size_t m = std::size_t(anz[j]);
    if (anz[j] != bnz[j] || std::memcmp(static_cast<const int*>(a->i) + ap[j], static_cast<const int*>(b->i) + bp[j], sizeof(int) * m))
      return bitwise = false, -1.0;
    bitwise = bitwise && std::memcmp(ax + ap[j], bx + bp[j], sizeof(double) * m) == 0;
    for (std::size_t t = 0; t < m; ++t) most = std::max(most, std::abs(ax[ap[j] + t] - bx[bp[j] + t]));
  }
  return most;
}

// `solver` computes g.A in g.order on `threads` worker threads; the count is set back to the default.
bool compute_on(int threads, SpdSolver& solver, const NestedGrid& g) {
  cf::set_thread_count(threads);
  const bool ok = solver.compute(g.A, &g.order);
  cf::set_thread_count(0);
  return ok;
}

}  // namespace

// compute() with a given order on two threads factorises from the numeric transpose made beside the
// analysis (counted: no transpose of its own) and its factor is the one-thread one's (here, with the
// rest too small for blocks, cholmod_factorize's bits) to the last bit; analyze() then factorize()
// of other values (2 A) makes its own transpose (the early one could hold A's values) and solves 2 A.
TEST(FlattenSolver, TransposeMadeBesideTheAnalysisGivesTheSequentialFactorBits) {
  const NestedGrid g = nested_grid();
  SpdSolver seq, par;
  ASSERT_TRUE(compute_on(1, seq, g));
  ASSERT_TRUE(compute_on(2, par, g));
  EXPECT_TRUE(par.early_transpose());
  EXPECT_EQ(par.threaded_transposes(), 0);
  EXPECT_FALSE(seq.rest_blocks() || par.rest_blocks());  // (the grid's rest: below kRestBlocksMinWork)
  const cholmod_factor *a = seq.factor(), *b = par.factor();
  ASSERT_TRUE(a && b && !a->is_super && !b->is_super);
  bool bitwise = false;
  EXPECT_EQ(factor_difference(a, b, bitwise), 0.0);
  EXPECT_TRUE(bitwise);
  const SpdSolver::SpMat twice = 2.0 * g.A;
  cf::set_thread_count(2);
  par.analyze(g.A, &g.order);
  ASSERT_TRUE(par.factorize(twice));
  EXPECT_FALSE(par.early_transpose());
  EXPECT_EQ(par.threaded_transposes(), 1);
  cf::set_thread_count(0);
  const Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(g.A.rows(), 0.5, 1.5);
  const SpdSolver::SpMat full = twice.selfadjointView<Eigen::Lower>();
  EXPECT_LT((full * par.solve(rhs) - rhs).norm(), 1e-9 * rhs.norm());
}
#endif

// A two-column solve is each column's own one-column solve to the last bit, for 1 and 2 threads,
// with a factor below the threaded-solve threshold (columns on the calling thread) and one above
// it (columns on the threads): the threshold cannot change a map.
TEST(FlattenSolver, TwoColumnSolveIsEachColumnsOwnSolveBelowAndAboveTheThreadedThreshold) {
  for (const int nx : {40, 300}) {
    const int nv = nx * nx;
    const auto E = cf::flat_detail::build_edges(grid_faces(nx, nx, 17));
    const SpdSolver::SpMat A = whole_grid_system(E, nx, nv);
    const std::vector<int> order = SpdSolver::nested_dissection_order(A);
    Eigen::MatrixXd b(nv, 2);
    for (int i = 0; i < nv; ++i) b(i, 0) = std::sin(0.013 * i) + 0.3, b(i, 1) = std::cos(0.007 * i);
    for (int threads : {1, 2}) {
      cf::set_thread_count(threads);
      SpdSolver solver;
      ASSERT_TRUE(solver.compute(A, &order));
      EXPECT_EQ(solver.factor_entries() >= SpdSolver::kThreadedSolveMinEntries, nx == 300) << nx;
      const Eigen::MatrixXd x = solver.solve(b);
      for (int c = 0; c < 2; ++c) {
        const Eigen::MatrixXd one = solver.solve(b.col(c));
        EXPECT_EQ(std::memcmp(x.col(c).data(), one.data(), sizeof(double) * std::size_t(nv)), 0) << nx << " " << c;
      }
    }
    cf::set_thread_count(0);
  }
}

// The islands a ring of faces encloses on a grid (the faces inside it), found from the ring's
// border, are the faces keep_largest_component drops from the ring's complement, whether no piece,
// one piece or every piece of the complement reaches the flood budget.
TEST(FlattenSolver, EnclosedFacesAreTheIslandsKeepLargestComponentDrops) {
  const int nx = 40;
  const std::vector<Tri> t = grid_faces(nx, nx, 23);
  const auto E = cf::flat_detail::build_edges(t);
  std::vector<char> in(t.size(), 0);
  std::vector<int> island;
  for (std::size_t f = 0; f < t.size(); ++f) {
    double x = 0, y = 0;
    for (int v : t[f]) x += (v % nx) / 3.0, y += (v / nx) / 3.0;
    const double r = std::hypot(x - 20, y - 20);
    in[f] = r >= 5 && r < 8;
    if (r < 5) island.push_back(int(f));
  }
  std::vector<char> keep(t.size());
  for (std::size_t f = 0; f < t.size(); ++f) keep[f] = !in[f];
  cf::flat_detail::keep_largest_component(E, keep);
  std::vector<int> dropped;
  for (std::size_t f = 0; f < t.size(); ++f)
    if (!in[f] && !keep[f]) dropped.push_back(int(f));
  ASSERT_EQ(dropped, island);
  ASSERT_GT(island.size(), 100u);
  for (std::size_t budget : {std::size_t(1), std::size_t(400), t.size()})
    EXPECT_EQ(cf::flat_detail::enclosed_by(E, in, budget), island) << "budget " << budget;
}

// A right-hand side of 5 columns is solved in 2 CHOLMOD calls (3 + 2 columns: L read twice, not 5
// times), every column the same bits as its own one-column solve, on a factor below
// kThreadedSolveMinEntries (groups on the calling thread) and on one above it (groups on threads).
TEST(FlattenSolver, ColumnsAreSolvedThreeToACallWithTheOneColumnBits) {
  for (const int nx : {40, 320}) {
    const int nv = nx * nx;
    const auto E = cf::flat_detail::build_edges(grid_faces(nx, nx, 11));
    SpdSolver s;
    ASSERT_TRUE(s.compute(whole_grid_system(E, nx, nv)));
    if (s.factor_flops() == 0) GTEST_SKIP() << "no CHOLMOD: Eigen's solve";
    EXPECT_EQ(s.factor_entries() >= SpdSolver::kThreadedSolveMinEntries, nx == 320);
    const Eigen::MatrixXd b = Eigen::MatrixXd::Random(nv, 5);
    const Eigen::MatrixXd x = s.solve(b);
    EXPECT_EQ(s.solve_calls(), 2);
    for (Eigen::Index c = 0; c < b.cols(); ++c) {
      const Eigen::MatrixXd alone = s.solve(b.col(c));
      EXPECT_EQ(alone, x.col(c)) << "column " << c << ", grid " << nx;
    }
    EXPECT_EQ(s.solve_calls(), 7);
  }
}

#ifdef COLONFLAT_HAVE_CHOLMOD
namespace {

// A tube of 300 x 300 vertices (90 000 unknowns), its grid Laplacian and nested dissection's order:
// the rows above the factorisation's two parts are a ring across the tube (1.4e8 of estimated work,
// above kRestBlocksMinWork): the rest is computed in blocks.
NestedGrid nested_tube() {
  const int na = 300, nz = 300, nv = na * nz;
  const auto E = cf::flat_detail::build_edges(tube_faces(na, nz));
  NestedGrid g{whole_grid_system(E, na, nv), {}};
  g.order = SpdSolver::nested_dissection_order(g.A);
  return g;
}

}  // namespace

// On the tube the rows above the two parts are computed in blocks (row solves, Schur complement,
// dense root), and the factor is the same bytes on 1, 2 and 4 threads; it solves the system.
TEST(FlattenSolver, RestInBlocksGivesTheSameFactorBitsOnOneTwoAndFourThreads) {
  const NestedGrid g = nested_tube();
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(g.A.rows(), -1.0, 2.0);
  SpdSolver solver[3];
  for (int t = 0; t < 3; ++t) {
    ASSERT_TRUE(compute_on(1 << t, solver[t], g));
    EXPECT_TRUE(solver[t].rest_blocks()) << (1 << t) << " threads";
  }
  for (int t : {1, 2}) {
    bool bitwise = false;
    EXPECT_EQ(factor_difference(solver[0].factor(), solver[t].factor(), bitwise), 0.0);
    EXPECT_TRUE(bitwise) << (1 << t) << " threads";
  }
  const SpdSolver::SpMat full = g.A.selfadjointView<Eigen::Lower>();
  EXPECT_LT((full * solver[1].solve(b) - b).norm(), 1e-9 * b.norm());
}

// The factor with the rest in blocks has the pattern of CHOLMOD's own factorisation (cholmod_factorize
// in the same order) and its entries to rounding (the rest's partial sums differ).
TEST(FlattenSolver, RestInBlocksIsCholmodsFactorToRounding) {
  const NestedGrid g = nested_tube();
  SpdSolver solver;
  ASSERT_TRUE(compute_on(2, solver, g));
  ASSERT_TRUE(solver.rest_blocks());
  cholmod_common c;
  cholmod_start(&c);
  c.supernodal = CHOLMOD_SIMPLICIAL, c.final_asis = 1, c.nmethods = 1, c.method[0].ordering = CHOLMOD_GIVEN, c.postorder = 0;
  cholmod_sparse view = cf::flat_detail::view_lower(g.A);
  cholmod_factor* ref = cholmod_analyze_p(&view, const_cast<int*>(g.order.data()), nullptr, 0, &c);
  ASSERT_TRUE(ref && cholmod_factorize(&view, ref, &c));
  bool bitwise = true;
  const double diff = factor_difference(ref, solver.factor(), bitwise);
  cholmod_free_factor(&ref, &c);
  cholmod_finish(&c);
  EXPECT_GE(diff, 0.0);  // the same pattern
  EXPECT_LT(diff, 1e-10);
}
#endif

// The conformal embedding (its vertex and face loops in blocks on the worker threads) is the same
// bits with 1 and 2 threads, on a tube of several blocks of faces: each vertex at (u, sign v P) x
// scale, each face's corner offsets whole periods with the face's centroid y in [0, P).
TEST(FlattenSolver, ConformalEmbeddingIsTheSameBitsOnOneAndTwoThreads) {
  using namespace cf::flat_detail;
  const Surface tube = bumpy_tube(48, 120);
  ASSERT_GT(tube.t.size(), 8192u);
  const Edges E = build_edges(tube.t);
  auto loops = boundary_loops(tube, E);
  ASSERT_EQ(loops.size(), 2u);
  const Harmonic h = solve_harmonic(tube, E, loops[0], loops[1], false);
  cf::set_thread_count(1);
  const Embedding one = embed_conformal(tube, E, h, -1.0, 1.7);
  cf::set_thread_count(2);
  const Embedding two = embed_conformal(tube, E, h, -1.0, 1.7);
  cf::set_thread_count(0);
  const double P = h.period * 1.7;
  ASSERT_EQ(one.pos.size(), two.pos.size());
  int differ = 0, off = 0;
  for (std::size_t v = 0; v < one.pos.size(); ++v) {
    differ += one.pos[v] != two.pos[v];
    off += one.pos[v] != cf::flat_detail::V2(h.u[Eigen::Index(v)] * 1.7, h.v[Eigen::Index(v)] * -P);
  }
  for (std::size_t f = 0; f < tube.t.size(); ++f) {
    differ += one.dy[f] != two.dy[f];
    const auto c = one.corners(tube, int(f));
    const double y = (c[0].y() + c[1].y() + c[2].y()) / 3;
    off += !(y >= 0 && y < P) || std::fmod(std::abs(one.dy[f][1]) / P + 0.5, 1.0) > 0.5 + 1e-9;
  }
  EXPECT_EQ(differ, 0);
  EXPECT_EQ(off, 0);
  EXPECT_EQ(one.period, P);
}
