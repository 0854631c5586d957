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

}  // namespace

// A region system solves the full symmetric system, though only its lower triangle is assembled
// (the diagonal summed per unknown): the same solution as the dense system assembled independently.
TEST(RegionSystem, LowerTriangleSolvesTheFullSystem) {
  const cf::test_shapes::SqueezedGrid g;
  std::vector<char> free_vertex(g.s.p.size());
  for (std::size_t v = 0; v < g.s.p.size(); ++v) free_vertex[v] = !g.fixed[v];
  std::vector<int> faces(g.s.t.size());
  for (std::size_t f = 0; f < faces.size(); ++f) faces[f] = int(f);
  const auto w = cf::flat_detail::corner_weights(g.s, faces);
  RegionSystem own;
  ASSERT_TRUE(own.build(g.s, free_vertex, faces, w));
  const int n = int(own.unknowns().size());
  ASSERT_GT(n, 100);
  const Eigen::MatrixXd b = Eigen::MatrixXd::Random(n, 2);
  const Eigen::MatrixXd want = dense_system(g, own, w).ldlt().solve(b);
  EXPECT_LT((own.solve_raw(b) - want).cwiseAbs().maxCoeff(), 1e-9);
}
