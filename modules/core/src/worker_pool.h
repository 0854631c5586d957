#pragma once
// The process's one pool of worker threads behind parallel_for / parallel_tasks (threads.h):
// workers are started once and sleep between calls, instead of a new std::thread per chunk per
// call (8 239 thread creations in one CT mask flatten, session 35). std only.
//
// run_indexed(count, threads, work) runs work(i) for every i in [0, count): the calling thread
// runs index 0 first, then it and at most threads - 1 pool workers take the next unclaimed index
// until none is left. Any thread may call it, also from inside a running index (a nested call):
// idle workers join the nested call, and callers waiting for their own call's helpers help the
// calls posted after theirs; when no thread is free the nested call's caller runs every index
// itself, so nesting never deadlocks (a caller waits only for indices other threads already run).
// The exception of the lowest index that threw is rethrown after every index ran. A child made by
// fork() gets a pool of its own (pthread_atfork), so it may call parallel_for like any process.
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace cf::core_detail {

struct PoolCall;

class WorkerPool {
 public:
  // The process's pool (never destroyed: its sleeping workers outlive static destruction).
  static WorkerPool& instance();

  // Runs every index as described above; the pool first grows or shrinks to `workers` threads
  // when no call is in flight (thread_count() - 1 from threads.cpp).
  void run_indexed(std::size_t count, int threads, std::size_t workers,
                   const std::function<void(std::size_t)>& work);

  // Starts or stops workers to reach `workers` (set_thread_count); skipped while a call is in
  // flight (the next call's own check resizes then).
  void resize(std::size_t workers);

  // Workers alive now, and worker threads ever started by this pool (tests, measurements).
  std::size_t workers() const;
  std::size_t threads_started() const;

 private:
  WorkerPool() = default;
  // fork() keeps only the forking thread: the pool's locks are taken before a fork (so that no
  // worker holds one at that instant), released after it in the parent, and the child gets a
  // fresh pool (the parent's workers do not exist there; the old pool is left as it is).
  static void before_fork();
  static void after_fork_in_parent();
  static void after_fork_in_child();
  void worker_loop(std::size_t index);
  PoolCall* joinable_call(std::size_t after);
  void help(PoolCall& call, std::unique_lock<std::mutex>& lock);
  void finish(PoolCall& call);

  mutable std::mutex mutex_;
  std::condition_variable wake_;      // workers: a call was posted, or the pool shrank
  std::condition_variable finished_;  // callers: a helper left a call
  std::vector<PoolCall*> open_;       // calls that still take helpers, newest last
  std::size_t in_flight_ = 0;         // calls posted and not yet returned
  std::size_t posted_ = 0;            // calls ever posted (PoolCall::serial)
  std::size_t callers_waiting_ = 0;   // callers in finish()'s wait
  std::size_t limit_ = 0;             // workers with an index >= limit_ leave
  std::size_t started_ = 0;
  std::atomic<std::size_t> size_{0};  // threads_.size(), read without the mutex
  std::vector<std::thread> threads_;
  std::mutex resize_mutex_;           // one resize at a time (it joins leaving workers)
};

}  // namespace cf::core_detail
