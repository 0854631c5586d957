#include "colonflat/core/threads.h"

#include <gtest/gtest.h>
#include <vtkSMPTools.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
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

// A task's own parallel_for / parallel_tasks (nested three deep) runs every index once and gives
// the serial result on 1, 2 and 4 threads (the pool's workers are shared by nested calls).
TEST_F(CoreThreads, NestedCallsGiveTheSerialResult) {
  auto compute = [] {
    std::vector<std::uint64_t> cell(6 * 5 * 40, 0);
    cf::parallel_for(6, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        std::vector<std::function<void()>> tasks;
        for (std::size_t j = 0; j < 5; ++j)
          tasks.push_back([&, i, j] {
            cf::parallel_for(40, [&](std::size_t k0, std::size_t k1) {
              for (std::size_t k = k0; k < k1; ++k) cell[(i * 5 + j) * 40 + k] += (i + 1) * 1000003 + j * 101 + k;
            });
          });
        cf::parallel_tasks(tasks);
      }
    });
    return cell;
  };
  cf::set_thread_count(1);
  const std::vector<std::uint64_t> serial = compute();
  for (std::size_t c = 0; c < serial.size(); ++c) ASSERT_NE(serial[c], 0u);
  for (int t : {2, 4}) {
    cf::set_thread_count(t);
    EXPECT_EQ(compute(), serial) << t << " threads";
  }
}

// Every call gets all its threads at once, nested or not: T tasks that each wait for the other
// T - 1 to start all meet (before the pool, each call started its own threads; this keeps that).
TEST_F(CoreThreads, EveryCallGetsItsThreadsAtOnce) {
  for (int t : {2, 4}) {
    cf::set_thread_count(t);
    std::atomic<int> met{0};
    auto meet = [t](std::atomic<int>& arrived) {  // true when all t arrived within 20 s
      ++arrived;
      const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(20);
      while (arrived.load() < t && std::chrono::steady_clock::now() < until) std::this_thread::yield();
      return arrived.load() >= t;
    };
    std::vector<std::atomic<int>> inner(static_cast<std::size_t>(t));
    cf::parallel_for(std::size_t(t), [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        std::vector<std::function<void()>> tasks(std::size_t(t), [&, i] { met += meet(inner[i]) ? 1 : 0; });
        cf::parallel_tasks(tasks);
      }
    });
    EXPECT_EQ(met.load(), t * t) << t << " threads";
  }
}

// Workers are kept: a thousand calls (plain and nested) start no more workers than one call can
// hold at once (2 threads: the outer call's helper and one per nested call, 3), where a thread per
// call would start 3 000. (Which calls start them depends on timing, so only the bound is asserted.)
TEST_F(CoreThreads, WorkersAreReusedAcrossCalls) {
  cf::set_thread_count(2);
  std::atomic<std::size_t> sum{0};
  const std::size_t before = cf::worker_threads_started();
  for (int r = 0; r < 1000; ++r)
    cf::parallel_for(4, [&](std::size_t b, std::size_t e) {
      sum += e - b;
      cf::parallel_for(2, [&](std::size_t b2, std::size_t e2) { sum += e2 - b2; });
    });
  EXPECT_LE(cf::worker_threads_started() - before, std::size_t(3));
  EXPECT_EQ(sum.load(), std::size_t(1000 * (4 + 2 * 2)));
}

// An exception thrown in a nested task reaches the outermost caller (the lowest index's), after
// every task ran; the pool then still works.
TEST_F(CoreThreads, NestedExceptionReachesTheCaller) {
  for (int t : {1, 2, 4}) {
    cf::set_thread_count(t);
    std::atomic<int> ran{0};
    try {
      std::vector<std::function<void()>> outer;
      for (int i = 0; i < 3; ++i)
        outer.push_back([&, i] {
          cf::parallel_tasks({[&] { ++ran; }, [&, i] {
                                ++ran;
                                if (i > 0) throw std::runtime_error("outer " + std::to_string(i));
                              }});
        });
      cf::parallel_tasks(outer);
      FAIL() << "no exception";
    } catch (const std::runtime_error& e) {
      EXPECT_STREQ(e.what(), "outer 1") << t << " threads";
    }
    EXPECT_EQ(ran.load(), 6) << t << " threads";
    std::atomic<int> after{0};
    cf::parallel_for(8, [&](std::size_t b, std::size_t e) { after += int(e - b); });
    EXPECT_EQ(after.load(), 8);
  }
}

// Two threads of the caller's own calling parallel_for at the same time each get every index once.
TEST_F(CoreThreads, TwoCallersAtOnce) {
  cf::set_thread_count(2);
  std::vector<std::atomic<int>> seen(2 * 500);
  auto caller = [&](std::size_t half) {
    for (int r = 0; r < 50; ++r)
      cf::parallel_for(500, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) ++seen[half * 500 + i];
      });
  };
  std::thread other(caller, 1);
  caller(0);
  other.join();
  for (auto& s : seen) EXPECT_EQ(s.load(), 50);
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
