#include "worker_pool.h"

#include <algorithm>
#include <atomic>
#include <exception>

#include <pthread.h>

namespace cf::core_detail {

// One run_indexed call: its indices, the next unclaimed one, and who helps. helpers_left and
// helping are guarded by the pool's mutex; the caller returns only once helping is 0, so a helper
// never touches a call that is gone.
struct PoolCall {
  PoolCall(std::size_t n, int threads, const std::function<void(std::size_t)>& w)
      : count(n), work(w), errors(n), helpers_left(std::size_t(std::max(1, threads) - 1)) {}

  void run(std::size_t i) {
    try {
      work(i);
    } catch (...) {
      errors[i] = std::current_exception();
    }
  }
  // Takes the next unclaimed index until none is left.
  void drain() {
    for (std::size_t i = next++; i < count; i = next++) run(i);
  }
  bool has_unclaimed() const { return next.load() < count; }

  const std::size_t count;
  const std::function<void(std::size_t)>& work;
  std::vector<std::exception_ptr> errors;
  std::atomic<std::size_t> next{1};  // index 0 is the caller's
  std::size_t helpers_left;
  std::size_t helping = 0;
  std::size_t serial = 0;  // posting order, from 1
};

namespace {
WorkerPool* g_pool = nullptr;  // deliberately never destroyed (sleeping workers outlive statics)
}  // namespace

WorkerPool& WorkerPool::instance() {
  static const bool made = [] {
    g_pool = new WorkerPool;  // NOLINT: never destroyed
    pthread_atfork(&WorkerPool::before_fork, &WorkerPool::after_fork_in_parent, &WorkerPool::after_fork_in_child);
    return true;
  }();
  (void)made;
  return *g_pool;
}

void WorkerPool::before_fork() {
  g_pool->resize_mutex_.lock();  // the order resize() takes them in
  g_pool->mutex_.lock();
}

void WorkerPool::after_fork_in_parent() {
  g_pool->mutex_.unlock();
  g_pool->resize_mutex_.unlock();
}

void WorkerPool::after_fork_in_child() {
  g_pool = new WorkerPool;  // NOLINT: the parent's pool (its threads absent here) is left, locked
}

void WorkerPool::run_indexed(std::size_t count, int threads, std::size_t workers,
                             const std::function<void(std::size_t)>& work) {
  if (count == 0) return;
  PoolCall call(count, threads, work);
  const bool shared = call.helpers_left > 0 && count > 1 && workers > 0;
  bool waiting = false;  // callers wait in finish() and may help this call
  if (shared) {
    if (size_.load() != workers) resize(workers);
    std::lock_guard<std::mutex> lock(mutex_);
    ++in_flight_;
    call.serial = ++posted_;
    open_.push_back(&call);
    waiting = callers_waiting_ > 0;
  }
  if (shared) wake_.notify_all();
  if (waiting) finished_.notify_all();
  call.run(0);
  call.drain();
  if (shared) finish(call);
  for (auto& e : call.errors)
    if (e) std::rethrow_exception(e);
}

// Closes the call to new helpers and waits for the ones still running an index; meanwhile the
// caller helps the calls posted after its own (those its helpers' indices nested), so that a
// nested loop whose poster found no idle worker still gets this thread once it is free.
void WorkerPool::finish(PoolCall& call) {
  std::unique_lock<std::mutex> lock(mutex_);
  open_.erase(std::find(open_.begin(), open_.end(), &call));
  for (;;) {
    PoolCall* other = nullptr;
    ++callers_waiting_;
    finished_.wait(lock, [&] { return call.helping == 0 || (other = joinable_call(call.serial)) != nullptr; });
    --callers_waiting_;
    if (!other) break;
    help(*other, lock);
  }
  --in_flight_;
}

// Runs indices of `call` as one of its helpers (the lock held on entry and on return).
void WorkerPool::help(PoolCall& call, std::unique_lock<std::mutex>& lock) {
  --call.helpers_left;
  ++call.helping;
  lock.unlock();
  call.drain();
  lock.lock();
  if (--call.helping == 0) finished_.notify_all();
}

// The newest open call posted after `after` that still takes a helper and has an index left
// (mutex held).
PoolCall* WorkerPool::joinable_call(std::size_t after) {
  for (auto it = open_.rbegin(); it != open_.rend() && (*it)->serial > after; ++it)
    if ((*it)->helpers_left > 0 && (*it)->has_unclaimed()) return *it;
  return nullptr;
}

void WorkerPool::worker_loop(std::size_t index) {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    PoolCall* call = nullptr;
    wake_.wait(lock, [&] { return index >= limit_ || (call = joinable_call(0)) != nullptr; });
    if (index >= limit_) return;
    help(*call, lock);
  }
}

// Starts or stops workers to reach `want`; only while no call is in flight (a nested or
// concurrent call keeps the workers it has: the call's own helper cap bounds the threads).
void WorkerPool::resize(std::size_t want) {
  std::lock_guard<std::mutex> serial(resize_mutex_);
  std::vector<std::thread> leaving;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (threads_.size() == want || in_flight_ > 0) return;
    limit_ = want;
    for (std::size_t k = threads_.size(); k < want; ++k) {
      threads_.emplace_back([this, k] { worker_loop(k); });
      ++started_;
    }
    for (std::size_t k = want; k < threads_.size(); ++k) leaving.push_back(std::move(threads_[k]));
    threads_.resize(want);
    size_.store(want);
  }
  wake_.notify_all();
  for (auto& t : leaving) t.join();
}

std::size_t WorkerPool::workers() const { return size_.load(); }

std::size_t WorkerPool::threads_started() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return started_;
}

}  // namespace cf::core_detail
