#include "colonflat/core/threads.h"

#include <pthread.h>
#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstdlib>
#include <exception>
#include <string>
#include <mutex>
#include <system_error>
#include <thread>

#include <vtkMultiThreader.h>
#include <vtkSMPTools.h>

namespace cf {

namespace {

std::atomic<int> g_threads{0};  // 0: the default

// One parallel_for / parallel_tasks call: work(i) for i in [0, count), each index claimed once by
// whichever thread (the caller or a lent worker) asks next.
struct Job {
  std::size_t count = 0;
  const std::function<void(std::size_t)>* work = nullptr;
  std::atomic<std::size_t> next{0};
  std::vector<std::exception_ptr> errors;  // per index
  int helpers = 0;                         // lent workers still inside run() (WorkerPool::mutex_)
  std::condition_variable done;            // helpers reached 0

  void run() {
    for (std::size_t i = next++; i < count; i = next++) {
      try {
        (*work)(i);
      } catch (...) {
        errors[i] = std::current_exception();
      }
    }
  }
};

// Worker threads started on demand and kept: a call that wants k helpers takes k idle workers and
// starts a new one for each it lacks, so every call gets as many threads at once as when each call
// started its own (a task that calls parallel_for gets its helpers too: no call waits for a worker
// another call holds, so nesting cannot deadlock). Idle workers sleep on a condition variable.
// The pool is never destroyed (its threads sleep through exit); a forked child starts a new one.
class WorkerPool {
 public:
  static WorkerPool& get() {
    static const bool registered = [] { return ::pthread_atfork(nullptr, nullptr, [] { instance() = new WorkerPool; }) == 0; }();
    (void)registered;
    return *instance();
  }
  // Lends `helpers` workers to `job` (job.helpers counts the ones that got it).
  void lend(Job& job, int helpers) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (int h = 0; h < helpers; ++h) {
      Worker* w = idle_.empty() ? start_worker() : take_idle();
      if (!w) break;  // no thread could be started: the caller does the rest
      w->job = &job;
      ++job.helpers;
      w->wake.notify_one();
    }
  }
  // Blocks until every worker lent to `job` left it.
  void wait(Job& job) {
    std::unique_lock<std::mutex> lock(mutex_);
    job.done.wait(lock, [&] { return job.helpers == 0; });
  }
  std::size_t started() const { return started_.load(); }

 private:
  struct Worker {
    Job* job = nullptr;  // set by lend(), cleared by the worker (mutex_)
    std::condition_variable wake;
  };
  static WorkerPool*& instance() {
    static WorkerPool* pool = new WorkerPool;
    return pool;
  }
  Worker* take_idle() {
    Worker* w = idle_.back();
    idle_.pop_back();
    return w;
  }
  Worker* start_worker() {
    auto* w = new Worker;
    try {
      std::thread(&WorkerPool::loop, this, w).detach();
    } catch (const std::system_error&) {
      delete w;
      return nullptr;
    }
    ++started_;
    return w;
  }
  // A worker's life: wait for a job, run its indices, be idle again, then tell the job's caller
  // (idle first, so that the caller's next call finds this worker).
  void loop(Worker* w) {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      w->wake.wait(lock, [w] { return w->job != nullptr; });
      Job* job = w->job;
      lock.unlock();
      job->run();
      lock.lock();
      w->job = nullptr;
      idle_.push_back(w);
      if (--job->helpers == 0) job->done.notify_one();
    }
  }

  std::mutex mutex_;
  std::vector<Worker*> idle_;
  std::atomic<std::size_t> started_{0};
};

// Runs work(i) for every i in [0, count) on `threads` threads (the caller and threads - 1 pool
// workers), each thread taking the next unclaimed index; rethrows the exception of the lowest
// index that threw.
void run_indexed(std::size_t count, int threads, const std::function<void(std::size_t)>& work) {
  Job job;
  job.count = count;
  job.work = &work;
  job.errors.resize(count);
  WorkerPool& pool = WorkerPool::get();
  if (threads > 1) pool.lend(job, threads - 1);
  job.run();
  pool.wait(job);
  for (auto& e : job.errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace

int default_thread_count() {
  if (const char* env = std::getenv("COLONFLAT_THREADS")) {
    char* end = nullptr;
    const long v = std::strtol(env, &end, 10);
    if (end != env && *end == '\0' && v > 0) return int(std::min<long>(v, 1024));
  }
  return std::max(1u, std::thread::hardware_concurrency());
}

int thread_count() {
  const int n = g_threads.load();
  return n > 0 ? n : default_thread_count();
}

namespace {

std::mutex g_listeners_mutex;
std::vector<ThreadCountListener>& listeners() {
  static std::vector<ThreadCountListener> all;
  return all;
}

// VTK's pools: vtkSMPTools (TBB here; fairing, flying edges) and vtkMultiThreader (threaded image
// filters such as the Gaussian smoothing of render).
void vtk_follows(int n) {
  vtkSMPTools::Initialize(n);
  vtkMultiThreader::SetGlobalMaximumNumberOfThreads(n);
}

}  // namespace

void set_thread_count(int n) {
  g_threads.store(n > 0 ? n : 0);
  const int now = thread_count();
  vtk_follows(now);
  std::lock_guard<std::mutex> lock(g_listeners_mutex);
  for (ThreadCountListener l : listeners()) l(now);
}

void add_thread_count_listener(ThreadCountListener listener) {
  {
    std::lock_guard<std::mutex> lock(g_listeners_mutex);
    for (ThreadCountListener l : listeners())
      if (l == listener) return;
    listeners().push_back(listener);
  }
  listener(thread_count());
}

void parallel_for(std::size_t n, const std::function<void(std::size_t, std::size_t)>& body, int max_threads) {
  if (n == 0) return;
  const std::size_t t = std::min<std::size_t>({std::size_t(thread_count()), std::size_t(std::max(1, max_threads)), n});
  if (t == 1) return body(0, n);
  run_indexed(t, int(t), [&](std::size_t c) { body(n * c / t, n * (c + 1) / t); });
}

void parallel_tasks(const std::vector<std::function<void()>>& tasks) {
  const int t = int(std::min<std::size_t>(std::size_t(thread_count()), tasks.size()));
  run_indexed(tasks.size(), std::max(1, t), [&](std::size_t i) { tasks[i](); });
}

std::size_t worker_threads_started() { return WorkerPool::get().started(); }

double process_cpu_seconds() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return double(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) + 1e-6 * double(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

}  // namespace cf
