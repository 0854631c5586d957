#include "colonflat/core/threads.h"

#include <gtest/gtest.h>
#include <vtkSMPTools.h>

#include <atomic>
#include <cstdlib>
#include <stdexcept>
#include <thread>
#include <vector>

namespace {

// Restores the default count after each test (the setting is process-wide).
class CoreThreads : public ::testing::Test {
 protected:
  void TearDown() override { cf::set_thread_count(0); }
};

// parallel_for visits every index exactly once, in contiguous chunks, for 1..7 threads and sizes 0..50.
TEST_F(CoreThreads, ParallelForCoversEveryIndexOnce) {
  for (int t = 1; t <= 7; ++t) {
    cf::set_thread_count(t);
    for (std::size_t n : {0u, 1u, 2u, 3u, 7u, 50u}) {
      std::vector<std::atomic<int>> seen(n);
      std::atomic<int> chunks{0};
      cf::parallel_for(n, [&](std::size_t b, std::size_t e) {
        ASSERT_LT(b, e);
        ++chunks;
        for (std::size_t i = b; i < e; ++i) ++seen[i];
      });
      for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(seen[i].load(), 1) << "t=" << t << " n=" << n << " i=" << i;
      EXPECT_EQ(std::size_t(chunks.load()), std::min<std::size_t>(std::size_t(t), n));
    }
  }
}

// The chunk boundaries depend only on n and the thread count: [n*c/T, n*(c+1)/T).
TEST_F(CoreThreads, ChunksAreTheDocumentedSplit) {
  cf::set_thread_count(3);
  std::vector<std::pair<std::size_t, std::size_t>> got(3);
  cf::parallel_for(10, [&](std::size_t b, std::size_t e) { got[b == 0 ? 0 : (b == 3 ? 1 : 2)] = {b, e}; });
  EXPECT_EQ(got[0], std::make_pair(std::size_t(0), std::size_t(3)));
  EXPECT_EQ(got[1], std::make_pair(std::size_t(3), std::size_t(6)));
  EXPECT_EQ(got[2], std::make_pair(std::size_t(6), std::size_t(10)));
}

// max_threads caps the chunk count below the setting.
TEST_F(CoreThreads, MaxThreadsCapsTheChunks) {
  cf::set_thread_count(6);
  std::atomic<int> chunks{0};
  cf::parallel_for(100, [&](std::size_t, std::size_t) { ++chunks; }, 2);
  EXPECT_EQ(chunks.load(), 2);
}

// An exception in a chunk reaches the caller (the lowest chunk's), after every chunk ran.
TEST_F(CoreThreads, ExceptionOfTheFirstFailingChunkIsRethrown) {
  cf::set_thread_count(4);
  std::atomic<int> ran{0};
  try {
    cf::parallel_for(4, [&](std::size_t b, std::size_t) {
      ++ran;
      if (b >= 1) throw std::runtime_error("chunk " + std::to_string(b));
    });
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "chunk 1");
  }
  EXPECT_EQ(ran.load(), 4);
}

// parallel_tasks runs each task once whatever the count, and rethrows the first task's error by index.
TEST_F(CoreThreads, TasksRunOnceAndRethrowByIndex) {
  for (int t : {1, 2, 5}) {
    cf::set_thread_count(t);
    std::vector<int> hits(9, 0);
    std::vector<std::function<void()>> tasks;
    for (int i = 0; i < 9; ++i) tasks.push_back([&hits, i] { hits[i] += 1; });
    cf::parallel_tasks(tasks);
    for (int h : hits) EXPECT_EQ(h, 1);
    tasks.push_back([] { throw std::runtime_error("late"); });
    tasks.insert(tasks.begin() + 2, [] { throw std::runtime_error("early"); });
    try {
      cf::parallel_tasks(tasks);
      FAIL() << "no exception";
    } catch (const std::runtime_error& e) {
      EXPECT_STREQ(e.what(), "early");
    }
  }
}

// The default is every core unless COLONFLAT_THREADS holds a positive integer; 0 restores it.
TEST_F(CoreThreads, DefaultFollowsTheEnvironment) {
  ::unsetenv("COLONFLAT_THREADS");
  EXPECT_EQ(cf::default_thread_count(), int(std::max(1u, std::thread::hardware_concurrency())));
  ::setenv("COLONFLAT_THREADS", "3", 1);
  EXPECT_EQ(cf::thread_count(), 3);
  ::setenv("COLONFLAT_THREADS", "zero", 1);
  EXPECT_EQ(cf::default_thread_count(), int(std::max(1u, std::thread::hardware_concurrency())));
  ::unsetenv("COLONFLAT_THREADS");
  cf::set_thread_count(5);
  EXPECT_EQ(cf::thread_count(), 5);
  cf::set_thread_count(0);
  EXPECT_EQ(cf::thread_count(), cf::default_thread_count());
}

}  // namespace

namespace {

int g_heard = -1;
void hear(int n) { g_heard = n; }

// The count reaches VTK's SMP pool and every registered listener (ITK's in colonflat_main), at
// registration and on every change, so --threads N bounds the libraries' pools as well.
TEST_F(CoreThreads, LibraryPoolsAndListenersFollowTheCount) {
  cf::set_thread_count(1);
  EXPECT_EQ(vtkSMPTools::GetEstimatedNumberOfThreads(), 1);
  cf::add_thread_count_listener(hear);
  EXPECT_EQ(g_heard, 1);
  cf::set_thread_count(2);
  EXPECT_EQ(vtkSMPTools::GetEstimatedNumberOfThreads(), 2);
  EXPECT_EQ(g_heard, 2);
  cf::add_thread_count_listener(hear);  // registered once: no second call per change
  cf::set_thread_count(0);
  EXPECT_EQ(g_heard, cf::default_thread_count());
}

}  // namespace
