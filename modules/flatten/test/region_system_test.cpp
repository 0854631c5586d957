// The region systems of the area correction and balancing (src/region_system.cpp).
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cstring>
#include <random>

#include "../src/flatten_internal.h"
#include "colonflat/core/threads.h"
#include "squeezed_grid.h"

namespace {

using cf::flat_detail::RegionSystem;

// The full symmetric system, assembled independently as a dense matrix: sum_f sum_k w_fk (e_a - e_b)(e_a - e_b)^T
// over the free rows.
Eigen::MatrixXd dense_system(const cf::test_shapes::SqueezedGrid& g, const RegionSystem& sys,
                             const std::vector<std::array<double, 3>>& w) {
  const int n = int(sys.unknowns().size());
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  for (std::size_t i = 0; i < sys.faces().size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const int a = sys.index(g.s.t[sys.faces()[i]][(k + 1) % 3]), b = sys.index(g.s.t[sys.faces()[i]][(k + 2) % 3]);
      if (a >= 0) A(a, a) += w[i][k];
      if (b >= 0) A(b, b) += w[i][k];
      if (a >= 0 && b >= 0) A(a, b) -= w[i][k], A(b, a) -= w[i][k];
    }
  return A;
}

// The squeezed grid's region system over all its faces (the vertices not fixed free), built with
// `vertex_order` when given; the largest difference between its solution of two random right-hand
// sides and the dense system's (`unknowns`: the system's size).
double error_against_dense(const std::vector<int>* vertex_order, int& unknowns) {
  const cf::test_shapes::SqueezedGrid g;
  std::vector<char> free_vertex(g.s.p.size());
  for (std::size_t v = 0; v < g.s.p.size(); ++v) free_vertex[v] = !g.fixed[v];
  std::vector<int> faces(g.s.t.size());
  for (std::size_t f = 0; f < faces.size(); ++f) faces[f] = int(f);
  const auto w = cf::flat_detail::corner_weights(g.s, faces);
  RegionSystem sys;
  if (!sys.build(g.s, free_vertex, faces, w, vertex_order)) return 1e300;
  unknowns = int(sys.unknowns().size());
  const Eigen::MatrixXd b = Eigen::MatrixXd::Random(unknowns, 2);
  const Eigen::MatrixXd want = dense_system(g, sys, w).ldlt().solve(b);
  return (sys.solve_raw(b) - want).cwiseAbs().maxCoeff();
}

}  // namespace

// A region system solves the full symmetric system, though only its lower triangle is assembled
// (the diagonal summed per unknown): the same solution as the dense system assembled independently.
TEST(RegionSystem, LowerTriangleSolvesTheFullSystem) {
  int n = 0;
  EXPECT_LT(error_against_dense(nullptr, n), 1e-9);
  EXPECT_GT(n, 100);
}

// A region system built with a given vertex order (a fill-reducing order of the whole surface, as a
// large band's nested dissection order) solves the same system: the dense system's solution to 1e-9,
// also when the order lists vertices that are not unknowns (fixed ones).
TEST(RegionSystem, GivenVertexOrderSolvesTheSameSystem) {
  const cf::test_shapes::SqueezedGrid g;
  std::vector<int> order(g.s.p.size());  // every vertex, in a shuffled order
  for (std::size_t v = 0; v < order.size(); ++v) order[v] = int(v);
  std::shuffle(order.begin(), order.end(), std::mt19937(5));
  int n = 0;
  EXPECT_LT(error_against_dense(&order, n), 1e-9);
  EXPECT_LT(std::size_t(n), g.s.p.size());  // some vertices of the order are not unknowns
}

// region_lower (the region system's matrix, its columns sorted and merged on the worker threads) is
// bit for bit the matrix Eigen's setFromTriplets assembles from the same terms in face order (what
// RegionSystem::build did before), for 1 and 2 threads: the faces shuffled (so an edge's two terms
// come far apart), the weights distinct, some vertices fixed, on a grid 4 x the squeezed grid's size.
TEST(RegionSystem, MatrixIsBitwiseTheTripletAssembly) {
  const cf::test_shapes::SqueezedGrid g(0.2, 4);
  std::vector<int> faces(g.s.t.size()), index(g.s.p.size(), -1);
  for (std::size_t f = 0; f < faces.size(); ++f) faces[f] = int(f);
  std::shuffle(faces.begin(), faces.end(), std::mt19937(11));
  std::vector<std::array<double, 3>> w(faces.size());
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> weight(0.01, 3.0);
  for (auto& fw : w) fw = {weight(rng), weight(rng), weight(rng)};
  int n = 0;
  for (std::size_t v = 0; v < index.size(); ++v)
    if (!g.fixed[v]) index[v] = n++;
  std::vector<Eigen::Triplet<double>> trip;  // the assembly RegionSystem::build used
  std::vector<double> diagonal(std::size_t(n), 0.0);
  for (std::size_t i = 0; i < faces.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const int a = index[g.s.t[faces[i]][(k + 1) % 3]], b = index[g.s.t[faces[i]][(k + 2) % 3]];
      if (a >= 0) diagonal[std::size_t(a)] += w[i][k];
      if (b >= 0) diagonal[std::size_t(b)] += w[i][k];
      if (a >= 0 && b >= 0) trip.emplace_back(std::max(a, b), std::min(a, b), -w[i][k]);
    }
  for (int u = 0; u < n; ++u) trip.emplace_back(u, u, diagonal[std::size_t(u)]);
  Eigen::SparseMatrix<double> want(n, n);
  want.setFromTriplets(trip.begin(), trip.end());
  ASSERT_GT(n, 3000);
  for (int threads : {1, 2}) {
    cf::set_thread_count(threads);
    const Eigen::SparseMatrix<double> A = cf::flat_detail::region_lower(g.s, faces, w, index, n);
    ASSERT_EQ(A.nonZeros(), want.nonZeros());
    ASSERT_TRUE(A.isCompressed());
    EXPECT_TRUE(std::equal(A.outerIndexPtr(), A.outerIndexPtr() + n + 1, want.outerIndexPtr())) << threads;
    EXPECT_TRUE(std::equal(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros(), want.innerIndexPtr())) << threads;
    EXPECT_EQ(std::memcmp(A.valuePtr(), want.valuePtr(), sizeof(double) * std::size_t(A.nonZeros())), 0) << threads;
  }
  cf::set_thread_count(0);
}
