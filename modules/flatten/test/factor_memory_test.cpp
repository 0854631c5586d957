// CHOLMOD's large blocks kept between factorisations and fresh ones faulted in up front
// (factor_memory.cpp): reuse by size, the bound on what is kept, zeroing, residency, and a second
// factorisation that takes the first one's memory and gives the same solution.
#include <gtest/gtest.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <cstring>
#include <vector>

#include "../src/factor_memory.h"
#include "../src/spd_solver.h"

namespace {

using cf::flat_detail::BlockCache;
using cf::flat_detail::SpdSolver;

constexpr std::size_t kMiB = std::size_t(1) << 20;

// How many pages of [p, p + bytes) are resident (mincore).
std::size_t resident_pages(void* p, std::size_t bytes) {
  const std::size_t page = std::size_t(sysconf(_SC_PAGESIZE));
  const std::uintptr_t begin = reinterpret_cast<std::uintptr_t>(p) & ~(page - 1);
  const std::uintptr_t end = reinterpret_cast<std::uintptr_t>(p) + bytes;
  std::vector<unsigned char> in((end - begin + page - 1) / page);
  if (mincore(reinterpret_cast<void*>(begin), end - begin, in.data()) != 0) return 0;
  std::size_t n = 0;
  for (unsigned char c : in) n += c & 1;
  return n;
}

// The 5-point Laplacian of an nx x ny grid plus the identity (positive definite), lower triangle.
SpdSolver::SpMat grid_system(int nx, int ny) {
  std::vector<Eigen::Triplet<double>> t;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int v = j * nx + i;
      t.emplace_back(v, v, 1.0 + (i > 0) + (i + 1 < nx) + (j > 0) + (j + 1 < ny));
      if (i + 1 < nx) t.emplace_back(v + 1, v, -1.0);
      if (j + 1 < ny) t.emplace_back(v + nx, v, -1.0);
    }
  SpdSolver::SpMat A(nx * ny, nx * ny);
  A.setFromTriplets(t.begin(), t.end());
  A.makeCompressed();
  return A;
}

}  // namespace

// A freed large block serves the next request of between half its size and its size, not a smaller
// one, and comes back zeroed when asked for by calloc; at most max_kept blocks are kept (the
// smallest given back first), trim() gives them all back.
TEST(FactorMemory, FreedLargeBlockServesTheNextRequestOfAboutItsSize) {
  BlockCache cache(1 * kMiB, 2);
  void* p = cache.allocate(4 * kMiB);
  ASSERT_NE(p, nullptr);
  std::memset(p, 0xab, 4 * kMiB);
  cache.release(p);
  EXPECT_EQ(cache.stats().kept, 1u);
  void* q = cache.allocate(3 * kMiB);  // 3 of 4 MiB: reused
  EXPECT_EQ(q, p);
  cache.release(q);
  void* small = cache.allocate(kMiB + kMiB / 2);  // below half of 4 MiB: new memory
  EXPECT_NE(small, p);
  auto* z = static_cast<unsigned char*>(cache.allocate_zeroed(5, kMiB / 2));  // 2.5 MiB: reused, zeroed
  EXPECT_EQ(static_cast<void*>(z), p);
  std::size_t nonzero = 0;
  for (std::size_t k = 0; k < 5 * kMiB / 2; ++k) nonzero += z[k] != 0;
  EXPECT_EQ(nonzero, 0u);
  const BlockCache::Stats s = cache.stats();
  EXPECT_EQ(s.reused, 2u);
  EXPECT_EQ(s.fresh, 2u);
  void* other = cache.allocate(2 * kMiB);
  cache.release(z);
  cache.release(small);
  cache.release(other);
  EXPECT_EQ(cache.stats().kept, 2u);  // the smallest of the three (1.5 MiB) given back, not the oldest
  EXPECT_EQ(cache.stats().kept_bytes, 4 * kMiB + 2 * kMiB);
  cache.trim();
  EXPECT_EQ(cache.stats().kept, 0u);
}

// A block grown by reallocate keeps its contents; a small block (below min_bytes) is never kept.
TEST(FactorMemory, ReallocatedBlockKeepsItsContentsAndSmallBlocksAreNotKept) {
  BlockCache cache(1 * kMiB, 2);
  auto* p = static_cast<unsigned char*>(cache.allocate(2 * kMiB));
  for (std::size_t k = 0; k < 2 * kMiB; ++k) p[k] = static_cast<unsigned char>(k * 7);
  auto* q = static_cast<unsigned char*>(cache.reallocate(p, 6 * kMiB));
  ASSERT_NE(q, nullptr);
  std::size_t differ = 0;
  for (std::size_t k = 0; k < 2 * kMiB; ++k) differ += q[k] != static_cast<unsigned char>(k * 7);
  EXPECT_EQ(differ, 0u);
  EXPECT_EQ(cache.stats().kept, 0u);  // grown in place or moved by realloc: nothing left behind
  EXPECT_EQ(cache.reallocate(q, 5 * kMiB), static_cast<void*>(q));  // already large enough: kept in place
  cache.release(q);
  cache.release(cache.allocate(kMiB / 2));
  EXPECT_EQ(cache.stats().kept, 1u);
  EXPECT_EQ(cache.stats().kept_bytes, 6 * kMiB);
}

// A fresh large block is handed out with every page already resident (faulted in by touch_pages on
// the worker threads), so the kernel's zeroing is not left to the caller's first, serial write.
TEST(FactorMemory, FreshLargeBlockIsResidentWhenHandedOut) {
  BlockCache cache;  // the defaults: blocks from 32 MiB on (always a fresh mapping in glibc)
  const std::size_t bytes = cf::flat_detail::kKeptBlockMinBytes + 8 * kMiB;
  void* p = cache.allocate(bytes);
  ASSERT_NE(p, nullptr);
  const std::size_t page = std::size_t(sysconf(_SC_PAGESIZE));
  EXPECT_GE(resident_pages(p, bytes), bytes / page);
  cache.release(p);
}

// The second of two factorisations of about the same size (the first map's, then the whole band's)
// takes the memory the first one's factor left instead of new pages, and solves to the same bits.
TEST(FactorMemory, SecondFactorisationTakesTheFirstFactorsMemory) {
#ifndef COLONFLAT_HAVE_CHOLMOD
  GTEST_SKIP() << "CHOLMOD not in this build";
#else
  const SpdSolver::SpMat A = grid_system(400, 400);
  const Eigen::MatrixXd b = Eigen::MatrixXd::Ones(A.rows(), 1);
  BlockCache& cache = cf::flat_detail::cholmod_block_cache();
  Eigen::MatrixXd first;
  BlockCache::Stats before;
  {
    SpdSolver solver;
    ASSERT_TRUE(solver.compute(A));
    ASSERT_GE(solver.factor_entries() * sizeof(double), cf::flat_detail::kKeptBlockMinBytes);  // a large factor
    first = solver.solve(b);
    cache.trim();
    before = cache.stats();
  }
  EXPECT_GE(cache.stats().kept, 1u);  // the factor's values (and its row indices when large enough)
  SpdSolver solver;
  ASSERT_TRUE(solver.compute(A));
  const BlockCache::Stats after = cache.stats();
  EXPECT_GE(after.reused, before.reused + 1);
  EXPECT_EQ(after.fresh, before.fresh);
  const Eigen::MatrixXd second = solver.solve(b);
  EXPECT_EQ((second - first).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_LT((A.selfadjointView<Eigen::Lower>() * second - b).norm(), 1e-8 * b.norm());
  cache.trim();
#endif
}
