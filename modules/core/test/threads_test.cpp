#include "colonflat/core/threads.h"

#include <gtest/gtest.h>
#include <vtkSMPTools.h>

#include <atomic>
#include <unistd.h>
#include <sys/wait.h>
#include <csignal>
#include <chrono>
#include <cstdlib>
#include <stdexcept>
#include <thread>
#include <utility>
#include <vector>

#include "../src/worker_pool.h"

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

namespace {

using Bounds = std::vector<std::pair<std::size_t, std::size_t>>;

// Every chunk's bounds, by chunk index, from one parallel_for call (each chunk must come once).
Bounds chunks_of(std::size_t n) {
  const std::size_t t = std::min<std::size_t>(std::size_t(cf::thread_count()), n);
  Bounds got(t, {0, 0});
  std::vector<std::atomic<int>> calls(t);
  std::atomic<bool> caller_ran_first{false};
  const auto caller = std::this_thread::get_id();
  cf::parallel_for(n, [&](std::size_t b, std::size_t e) {
    std::size_t c = 0;
    while (c < t && n * c / t != b) ++c;  // the chunk whose documented start is b
    if (c == t) return;
    ++calls[c];
    got[c] = {b, e};
    if (c == 0 && std::this_thread::get_id() == caller) caller_ran_first = true;
  });
  for (std::size_t c = 0; c < t; ++c) EXPECT_EQ(calls[c].load(), 1) << "chunk " << c;
  EXPECT_TRUE(n == 0 || caller_ran_first.load());
  return got;
}

// The pool runs every chunk exactly once, with the documented bounds [n c/T, n (c+1)/T), chunk 0
// on the calling thread, on 1, 2, 3 and 8 threads.
TEST_F(CoreThreads, PoolRunsEveryChunkOnceWithTheDocumentedBounds) {
  for (int t : {1, 2, 3, 8}) {
    cf::set_thread_count(t);
    for (std::size_t n : {1u, 2u, 5u, 8u, 9u, 1000u}) {
      const Bounds got = chunks_of(n);
      const std::size_t T = std::min<std::size_t>(std::size_t(t), n);
      ASSERT_EQ(got.size(), T);
      for (std::size_t c = 0; c < T; ++c)
        EXPECT_EQ(got[c], std::make_pair(n * c / T, n * (c + 1) / T)) << "t=" << t << " n=" << n << " c=" << c;
    }
  }
}

// A parallel_for inside a parallel_for chunk, and inside parallel_tasks, completes (no deadlock)
// and covers its indices once, with as many threads as chunks or fewer.
TEST_F(CoreThreads, NestedCallsComplete) {
  for (int t : {2, 3, 8}) {
    cf::set_thread_count(t);
    std::vector<std::atomic<int>> seen(64 * 100);
    cf::parallel_for(64, [&](std::size_t b, std::size_t e) {
      for (std::size_t o = b; o < e; ++o)
        cf::parallel_for(100, [&](std::size_t ib, std::size_t ie) {
          for (std::size_t i = ib; i < ie; ++i) ++seen[o * 100 + i];
        });
    });
    for (auto& s : seen) EXPECT_EQ(s.load(), 1);
    std::atomic<int> inner{0};
    std::vector<std::function<void()>> tasks(5, [&] {
      cf::parallel_for(7, [&](std::size_t b, std::size_t e) {
        cf::parallel_tasks({[&] { inner += int(e - b); }});
      });
    });
    cf::parallel_tasks(tasks);
    EXPECT_EQ(inner.load(), 35);
  }
}

// set_thread_count(n) leaves n - 1 pool workers (none for 1), and calls in a row start no new
// thread: the pool's workers persist between calls.
TEST_F(CoreThreads, SetThreadCountResizesThePersistentPool) {
  auto& pool = cf::core_detail::WorkerPool::instance();
  for (int t : {3, 5, 2, 1, 4}) {
    cf::set_thread_count(t);
    EXPECT_EQ(pool.workers(), std::size_t(t - 1)) << "t=" << t;
    const std::size_t started = pool.threads_started();
    for (int k = 0; k < 200; ++k) cf::parallel_for(100, [](std::size_t, std::size_t) {});
    EXPECT_EQ(pool.threads_started(), started) << "t=" << t;
    EXPECT_EQ(pool.workers(), std::size_t(t - 1));
  }
  ::setenv("COLONFLAT_THREADS", "3", 1);  // a default changed without set_thread_count: the next call resizes
  cf::set_thread_count(0);
  ::setenv("COLONFLAT_THREADS", "6", 1);
  cf::parallel_for(100, [](std::size_t, std::size_t) {});
  EXPECT_EQ(pool.workers(), 5u);
  ::unsetenv("COLONFLAT_THREADS");
}

// An exception in chunk 0 (the caller's) reaches the caller only after the other chunks, still
// running, finished; on 2, 3 and 8 threads.
TEST_F(CoreThreads, ExceptionIsRethrownAfterEveryChunkFinished) {
  for (int t : {2, 3, 8}) {
    cf::set_thread_count(t);
    std::atomic<int> finished{0};
    try {
      cf::parallel_for(std::size_t(t), [&](std::size_t b, std::size_t) {
        if (b == 0) throw std::runtime_error("chunk 0");
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
        ++finished;
      });
      FAIL() << "no exception";
    } catch (const std::runtime_error& e) {
      EXPECT_STREQ(e.what(), "chunk 0");
    }
    EXPECT_EQ(finished.load(), t - 1) << "t=" << t;
  }
}

// Many tiny calls in a row, from two threads at once, stay correct: every sum is the brute-force one.
TEST_F(CoreThreads, ManyTinyCallsStayCorrect) {
  cf::set_thread_count(3);
  auto calls = [](std::size_t first) {
    for (std::size_t k = 0; k < 20000; ++k) {
      const std::size_t n = 1 + (first + k) % 9;
      std::vector<std::size_t> part(n, 0);
      cf::parallel_for(n, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) part[i] = i + k;
      });
      std::size_t sum = 0;
      for (std::size_t p : part) sum += p;
      if (sum != n * (n - 1) / 2 + n * k) return false;
    }
    return true;
  };
  bool other_ok = false;
  std::thread other([&] { other_ok = calls(4); });
  EXPECT_TRUE(calls(0));
  other.join();
  EXPECT_TRUE(other_ok);
}

}  // namespace

namespace {

// parallel_indices runs every index once, the caller taking index 0, on 1, 2, 3 and 8 threads; and
// with max_threads 1 all on the caller.
TEST_F(CoreThreads, IndicesRunOnceWithIndexZeroOnTheCaller) {
  for (int t : {1, 2, 3, 8}) {
    cf::set_thread_count(t);
    for (std::size_t n : {1u, 2u, 7u, 64u}) {
      std::vector<std::atomic<int>> seen(n);
      std::atomic<bool> zero_on_caller{false};
      const auto caller = std::this_thread::get_id();
      cf::parallel_indices(n, [&](std::size_t i) {
        ++seen[i];
        if (i == 0) zero_on_caller = std::this_thread::get_id() == caller;
      });
      for (auto& s : seen) EXPECT_EQ(s.load(), 1) << "t=" << t << " n=" << n;
      EXPECT_TRUE(zero_on_caller.load());
    }
    std::atomic<int> elsewhere{0};
    const auto caller = std::this_thread::get_id();
    cf::parallel_indices(50, [&](std::size_t) { elsewhere += std::this_thread::get_id() != caller; }, 1);
    EXPECT_EQ(elsewhere.load(), 0);
  }
}

// A helper that stalls in its first index does not hold the others: the caller takes every other
// index meanwhile (fixed halves, as parallel_for's chunks, would leave 8 of 16 to the stalled helper).
TEST_F(CoreThreads, IndicesGoToTheThreadThatIsFree) {
  cf::set_thread_count(2);
  const auto caller = std::this_thread::get_id();
  std::atomic<bool> stalled{false};
  std::atomic<int> on_caller{0};
  cf::parallel_indices(16, [&](std::size_t) {
    if (std::this_thread::get_id() == caller) {
      ++on_caller;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    } else if (!stalled.exchange(true)) {
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
  });
  EXPECT_GE(on_caller.load(), 15);
}

// A child made by fork() (as the robustness tests' run-as-nobody does) while the pool's workers
// exist and another thread keeps them busy gets a working pool: its parallel_for, after a resize,
// sums every index, and it exits within the time limit (before pthread_atfork the child joined
// the parent's absent workers or waited on a lock one of them held at the fork, and hung).
TEST_F(CoreThreads, ForkedChildRunsParallelLoopsOnAPoolOfItsOwn) {
  cf::set_thread_count(2);
  std::atomic<bool> stop{false};
  std::thread busy([&] {
    while (!stop) cf::parallel_for(64, [](std::size_t, std::size_t) {});
  });
  int hung_or_wrong = 0;
  for (int k = 0; k < 20; ++k) {
    const pid_t child = ::fork();
    if (child == 0) {
      cf::set_thread_count(3);
      std::atomic<long> sum{0};
      cf::parallel_for(1000, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) sum += long(i);
      });
      ::_exit(sum.load() == 999L * 1000 / 2 ? 0 : 3);
    }
    int status = -1;
    pid_t got = 0;
    for (int ms = 0; ms < 20000 && got == 0; ms += 10) {
      got = ::waitpid(child, &status, WNOHANG);
      if (got == 0) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    if (got == 0) ::kill(child, SIGKILL), ::waitpid(child, &status, 0);
    hung_or_wrong += !(got == child && WIFEXITED(status) && WEXITSTATUS(status) == 0);
  }
  stop = true;
  busy.join();
  EXPECT_EQ(hung_or_wrong, 0);
}

}  // namespace
