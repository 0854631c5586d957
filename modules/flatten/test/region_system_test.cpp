// The region systems of the area correction and balancing (src/region_system.cpp).
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <algorithm>
#include <random>

#include "../src/flatten_internal.h"
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
