// TreeSolve: the simplicial LDL^T solve split over two threads along the elimination tree is bit
// for bit CHOLMOD's own solve, and SpdSolver takes it for one group of columns of a large factor.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "../src/spd_solver.h"
#include "../src/tree_solve.h"
#include "colonflat/core/threads.h"

#ifdef COLONFLAT_HAVE_CHOLMOD
namespace {

using cf::flat_detail::SpdSolver;

// The Laplacian of a triangulated tube of nz rings of na vertices (edge weights varied by index),
// plus 1e-3 on the diagonal: positive definite, a colon band's shape in small.
SpdSolver::SpMat tube_system(int na, int nz) {
  std::vector<Eigen::Triplet<double>> trip;
  const auto edge = [&](int a, int b) {
    const double w = 1.0 + 0.37 * ((a * 7 + b * 3) % 5);
    trip.emplace_back(a, a, w), trip.emplace_back(b, b, w), trip.emplace_back(std::max(a, b), std::min(a, b), -w);
  };
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < na; ++i) {
      const int a = j * na + i, b = j * na + (i + 1) % na;
      edge(a, b);
      if (j + 1 < nz) edge(a, a + na), edge(a, b + na);
    }
  const int n = na * nz;
  for (int v = 0; v < n; ++v) trip.emplace_back(v, v, 1e-3);
  SpdSolver::SpMat A(n, n);
  A.setFromTriplets(trip.begin(), trip.end());  // lower triangle
  return A;
}

// x = A^-1 b by cholmod_solve(CHOLMOD_A) with the solver's factor (the reference bits).
Eigen::MatrixXd cholmod_reference(const SpdSolver& s, const Eigen::MatrixXd& b) {
  cholmod_common c;
  cholmod_start(&c);
  cholmod_dense rhs{};
  rhs.nrow = std::size_t(b.rows()), rhs.ncol = std::size_t(b.cols()), rhs.nzmax = rhs.nrow * rhs.ncol, rhs.d = rhs.nrow;
  rhs.x = const_cast<double*>(b.data()), rhs.xtype = CHOLMOD_REAL, rhs.dtype = CHOLMOD_DOUBLE;
  cholmod_dense* x = cholmod_solve(CHOLMOD_A, const_cast<cholmod_factor*>(s.factor()), &rhs, &c);
  Eigen::MatrixXd out = Eigen::Map<const Eigen::MatrixXd>(static_cast<const double*>(x->x), b.rows(), b.cols());
  cholmod_free_dense(&x, &c);
  cholmod_finish(&c);
  return out;
}

// TreeSolve's x for b with s's factor, on `threads` threads (b permuted into the factor's row form).
Eigen::MatrixXd tree_solution(const SpdSolver& s, const cf::flat_detail::TreeSolve& plan, const Eigen::MatrixXd& b, int threads) {
  const std::size_t n = std::size_t(b.rows()), k = std::size_t(b.cols());
  const int* perm = static_cast<const int*>(s.factor()->Perm);
  std::vector<double> y(n * k);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t c = 0; c < k; ++c) y[i * k + c] = b(perm[i], Eigen::Index(c));
  cf::set_thread_count(threads);
  plan.solve(y.data(), int(k));
  cf::set_thread_count(0);
  Eigen::MatrixXd x(b.rows(), b.cols());
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t c = 0; c < k; ++c) x(perm[i], Eigen::Index(c)) = y[i * k + c];
  return x;
}

bool same_bits(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         std::memcmp(a.data(), b.data(), sizeof(double) * std::size_t(a.size())) == 0;
}

}  // namespace

// On a tube's factor in nested dissection order and in AMD's (whose parts and rest interleave in
// the column order), TreeSolve's x for 1, 2 and 3 right-hand sides on 1 and 2 threads is
// cholmod_solve's to the last bit; both parts and the rest hold columns and the parts keep terms
// for the rest's rows (the split is exercised), and x solves the system.
TEST(FlattenTreeSolve, SolveOnOneAndTwoThreadsIsCholmodsSolveBitwise) {
  const SpdSolver::SpMat A = tube_system(48, 90);
  const SpdSolver::SpMat full = A.selfadjointView<Eigen::Lower>();
  const std::vector<int> nested = SpdSolver::nested_dissection_order(A);
  for (const std::vector<int>* order : {&nested, static_cast<const std::vector<int>*>(nullptr)}) {
    SpdSolver s;
    cf::set_thread_count(1);
    ASSERT_TRUE(s.compute(A, order));
    cf::set_thread_count(0);
    const cf::flat_detail::TreeSolve plan(s.factor());
    ASSERT_TRUE(plan.usable());
    EXPECT_GT(plan.part_entries(0), 0u);
    EXPECT_GT(plan.part_entries(1), 0u);
    EXPECT_GT(plan.rest_entries(), 0u);
    EXPECT_GT(plan.kept_terms(), 0u);
    for (int k = 1; k <= cf::flat_detail::TreeSolve::kMaxColumns; ++k) {
      Eigen::MatrixXd b(A.rows(), k);
      for (Eigen::Index i = 0; i < b.rows(); ++i)
        for (int c = 0; c < k; ++c) b(i, c) = std::sin(0.013 * double(i) * (c + 1)) + 0.3 * c;
      const Eigen::MatrixXd ref = cholmod_reference(s, b);
      for (int threads : {1, 2}) EXPECT_TRUE(same_bits(tree_solution(s, plan, b, threads), ref)) << k << " columns, " << threads << " threads, " << (order ? "nested" : "AMD");
      EXPECT_LT((full * ref - b).norm(), 1e-8 * b.norm());
    }
  }
}

// SpdSolver on two threads solves one group of columns of a factor above kThreadedSolveMinEntries
// with TreeSolve from its second solve on (counted), with the bits of the one-thread solve
// (CHOLMOD's); below the threshold, and on one thread, it does not.
TEST(FlattenTreeSolve, LargeFactorsGroupIsSolvedOnTheTreeWithTheOneThreadBits) {
  for (const int nz : {10, 500}) {
    const SpdSolver::SpMat A = tube_system(300, nz);
    const std::vector<int> order = SpdSolver::nested_dissection_order(A);
    Eigen::MatrixXd b(A.rows(), 2);
    for (Eigen::Index i = 0; i < b.rows(); ++i) b(i, 0) = std::cos(0.007 * double(i)), b(i, 1) = 1.0 / (1.0 + double(i % 97));
    Eigen::MatrixXd x[2];
    for (int threads : {1, 2}) {
      cf::set_thread_count(threads);
      SpdSolver s;
      ASSERT_TRUE(s.compute(A, &order));
      const bool large = s.factor_entries() >= SpdSolver::kThreadedSolveMinEntries;
      EXPECT_EQ(large, nz == 500);
      const Eigen::MatrixXd first = s.solve(b);
      EXPECT_EQ(s.tree_solves(), 0);
      x[threads - 1] = s.solve(b);
      EXPECT_EQ(s.tree_solves(), large && threads == 2 ? 1 : 0) << nz << " rings, " << threads << " threads";
      EXPECT_TRUE(same_bits(first, x[threads - 1]));
    }
    cf::set_thread_count(0);
    EXPECT_TRUE(same_bits(x[0], x[1])) << nz;
  }
}
#endif
