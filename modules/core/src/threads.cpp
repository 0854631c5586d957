#include "colonflat/core/threads.h"

#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <exception>
#include <string>
#include <mutex>
#include <thread>

#include <vtkMultiThreader.h>
#include <vtkSMPTools.h>

#include "worker_pool.h"

namespace cf {

namespace {

std::atomic<int> g_threads{0};  // 0: the default

// Runs work(i) for every i in [0, count) on `threads` threads (the caller is one of them and runs
// index 0) of the process's persistent pool (worker_pool.h), sized thread_count() - 1; rethrows the
// exception of the lowest index that threw.
void run_indexed(std::size_t count, int threads, const std::function<void(std::size_t)>& work) {
  core_detail::WorkerPool::instance().run_indexed(count, threads, std::size_t(thread_count() - 1), work);
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
  core_detail::WorkerPool::instance().resize(std::size_t(now - 1));
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

void parallel_indices(std::size_t n, const std::function<void(std::size_t)>& body, int max_threads) {
  const std::size_t t = std::min<std::size_t>({std::size_t(thread_count()), std::size_t(std::max(1, max_threads)), n});
  run_indexed(n, int(std::max<std::size_t>(1, t)), body);
}

void parallel_tasks(const std::vector<std::function<void()>>& tasks) {
  parallel_indices(tasks.size(), [&](std::size_t i) { tasks[i](); });
}

double process_cpu_seconds() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return double(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) + 1e-6 * double(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

}  // namespace cf
