// The nested dissection order split at METIS's top vertex separator (metis_order.cpp): its shape,
// its independence of threads and timing (per-thread rand()), and its fill against the one-call order.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <thread>
#include <vector>

#include "../src/metis_order.h"
#include "../src/spd_solver.h"
#include "colonflat/core/threads.h"

namespace {

using cf::flat_detail::MetisSpMat;
using cf::flat_detail::SpdSolver;

// A closed tube: `along` rings of `around` vertices, each quad split in two; vertex j*around + i.
struct Tube {
  int around, along;
  std::vector<std::pair<int, int>> edges;
};

Tube tube(int around, int along) {
  Tube t{around, along, {}};
  for (int j = 0; j < along; ++j)
    for (int i = 0; i < around; ++i) {
      const int v = j * around + i, right = j * around + (i + 1) % around;
      t.edges.emplace_back(v, right);
      if (j + 1 < along) t.edges.emplace_back(v, v + around), t.edges.emplace_back(v, right + around);
    }
  return t;
}

// The tube's faces: each quad (v, right, right + around, v + around) split along (v, right + around).
std::vector<std::array<int, 3>> tube_faces(const Tube& t) {
  std::vector<std::array<int, 3>> faces;
  for (int j = 0; j + 1 < t.along; ++j)
    for (int i = 0; i < t.around; ++i) {
      const int v = j * t.around + i, right = j * t.around + (i + 1) % t.around;
      faces.push_back({v, right, right + t.around});
      faces.push_back({v, right + t.around, v + t.around});
    }
  return faces;
}

// Unit graph Laplacian + I of the tube (symmetric positive definite, both triangles stored).
MetisSpMat tube_system(const Tube& t) {
  const int n = t.around * t.along;
  std::vector<Eigen::Triplet<double>> trip;
  for (int v = 0; v < n; ++v) trip.emplace_back(v, v, 1.0);
  for (auto [a, b] : t.edges)
    trip.emplace_back(a, a, 1.0), trip.emplace_back(b, b, 1.0), trip.emplace_back(a, b, -1.0),
        trip.emplace_back(b, a, -1.0);
  MetisSpMat A(n, n);
  A.setFromTriplets(trip.begin(), trip.end());
  A.makeCompressed();
  return A;
}

bool is_permutation(std::vector<int> order, int n) {
  std::sort(order.begin(), order.end());
  for (int k = 0; k < n; ++k)
    if (order.size() != std::size_t(n) || order[std::size_t(k)] != k) return false;
  return true;
}

}  // namespace

// The split order is a permutation: side 0, side 1, then a separator that really separates (no
// edge joins the two sides), both sides non-empty and the separator about one ring of the tube.
TEST(MetisOrder, SplitOrderIsSideSideSeparatorAndTheSeparatorSeparates) {
  if (!cf::flat_detail::metis_direct_available()) GTEST_SKIP() << "built without libmetis-dev";
  const Tube t = tube(40, 120);
  const int n = t.around * t.along;
  const cf::flat_detail::SplitOrder s = cf::flat_detail::metis_split_order(tube_system(t));
  ASSERT_TRUE(is_permutation(s.order, n));
  EXPECT_GT(s.first_side, 0);
  EXPECT_LT(s.first_side + s.separator, n);
  EXPECT_GE(s.separator, t.around / 2);  // a closed loop around the tube, each vertex spanning <= 2 columns
  EXPECT_LE(s.separator, 2 * t.around);
  std::vector<int> side(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) side[std::size_t(s.order[std::size_t(k)])] = k < s.first_side ? 0 : k < n - s.separator ? 1 : 2;
  for (auto [a, b] : t.edges) EXPECT_FALSE(side[std::size_t(a)] + side[std::size_t(b)] == 1) << a << "-" << b;
}

// Two split orders computed at once on two threads are each the order computed alone, with one or
// two worker threads per order; METIS's rand() calls reach the per-thread generator (counted, so
// that the comparison is not of orders that never drew a random number).
TEST(MetisOrder, OrdersAtTheSameTimeOnAnyThreadCountAreEachTheOrderAlone) {
  if (!cf::flat_detail::metis_direct_available()) GTEST_SKIP() << "built without libmetis-dev";
  const MetisSpMat A[2] = {tube_system(tube(50, 160)), tube_system(tube(56, 150))};
  cf::set_thread_count(1);
  const std::uint64_t before = cf::flat_detail::metis_rand_calls();
  const std::vector<int> alone0 = cf::flat_detail::metis_split_dissection_order(A[0]);
  EXPECT_GT(cf::flat_detail::metis_rand_calls(), before + 1000);  // every side's METIS_NodeND ran here
  const std::vector<int> alone1 = cf::flat_detail::metis_split_dissection_order(A[1]);
  ASSERT_FALSE(alone0.empty());
  EXPECT_NE(alone0, std::vector<int>(alone0.size()));
  for (int threads : {1, 2, 2}) {
    cf::set_thread_count(threads);
    std::vector<int> at_once1;
    std::uint64_t other_calls = 0;
    std::thread other([&] {
      at_once1 = cf::flat_detail::metis_split_dissection_order(A[1]);
      other_calls = cf::flat_detail::metis_rand_calls();
    });
    const std::vector<int> at_once0 = cf::flat_detail::metis_split_dissection_order(A[0]);
    other.join();
    EXPECT_GT(other_calls, 1000u) << threads << " threads";
    EXPECT_EQ(at_once0, alone0) << threads << " threads";
    EXPECT_EQ(at_once1, alone1) << threads << " threads";
  }
  cf::set_thread_count(0);
}

// The vertex graph built from a tube's faces (most edges in two faces) is the graph of its
// Laplacian: each vertex's neighbours once, ascending; and the split order of that graph is the
// Laplacian's split order element for element (its postorder read from the graph's lower triangle).
TEST(MetisOrder, VertexGraphOfTheFacesOrdersAsTheirLaplacian) {
  const Tube t = tube(50, 160);
  const int n = t.around * t.along;
  const cf::flat_detail::VertexGraph g = cf::flat_detail::vertex_graph(tube_faces(t), n);
  std::vector<std::vector<int>> adjacent(static_cast<std::size_t>(n));
  for (auto [a, b] : t.edges) adjacent[std::size_t(a)].push_back(b), adjacent[std::size_t(b)].push_back(a);
  ASSERT_EQ(g.size(), n);
  int differ = 0;
  for (int v = 0; v < n; ++v) {
    std::sort(adjacent[std::size_t(v)].begin(), adjacent[std::size_t(v)].end());
    differ += std::vector<int>(g.adjncy.begin() + g.xadj[std::size_t(v)], g.adjncy.begin() + g.xadj[std::size_t(v) + 1]) !=
              adjacent[std::size_t(v)];
  }
  EXPECT_EQ(differ, 0);
  if (!cf::flat_detail::metis_direct_available()) GTEST_SKIP() << "built without libmetis-dev";
  const std::vector<int> from_faces = cf::flat_detail::metis_split_dissection_order(g);
  ASSERT_TRUE(is_permutation(from_faces, n));
  EXPECT_EQ(from_faces, cf::flat_detail::metis_split_dissection_order(tube_system(t)));
}

#ifdef COLONFLAT_HAVE_CHOLMOD
// On a tube the split order's factorisation costs at most 1.25 x the flops of cholmod_metis's
// one-call order (the top separator is METIS's own first bisection either way), and less than AMD's.
TEST(MetisOrder, SplitOrderFillIsCloseToTheOneCallOrder) {
  if (!cf::flat_detail::metis_direct_available()) GTEST_SKIP() << "built without libmetis-dev";
  MetisSpMat A = tube_system(tube(120, 300));
  const int n = int(A.rows());
  MetisSpMat lower = A.triangularView<Eigen::Lower>();
  lower.makeCompressed();
  const std::vector<int> one_call = SpdSolver::one_call_dissection_order(lower);
  ASSERT_TRUE(is_permutation(one_call, n));
  const std::vector<int> split = cf::flat_detail::metis_split_dissection_order(A);
  ASSERT_TRUE(is_permutation(split, n));
  SpdSolver s_split, s_one, s_amd;
  s_split.analyze(lower, &split);
  s_one.analyze(lower, &one_call);
  s_amd.analyze(lower);
  EXPECT_LE(s_split.factor_flops(), 1.25 * s_one.factor_flops());
  EXPECT_LT(s_split.factor_flops(), s_amd.factor_flops());
  RecordProperty("split_over_one_call_flops", std::to_string(s_split.factor_flops() / s_one.factor_flops()));
  std::printf("flops split %.4g one-call %.4g AMD %.4g\n", s_split.factor_flops(), s_one.factor_flops(),
              s_amd.factor_flops());
}
#endif
