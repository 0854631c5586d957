#pragma once
// Internal to the denoise module: persistent helper threads that run the jobs of one step at once
// (the set-up's analysis beside the copy; the group searches of one batch). No thread is started
// per job: a batch of small searches costs less than starting threads (cf::parallel_for does).
#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "colonflat/denoise/run_both.h"

namespace cf::detail {

class SearchWorker {
 public:
  // `threads` workers in all: the caller and threads - 1 helpers.
  explicit SearchWorker(int threads) {
    for (int t = 1; t < threads; ++t) helpers_.emplace_back([this, t] { loop(t); });
  }
  ~SearchWorker() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    for (auto& h : helpers_) h.join();
  }
  SearchWorker(const SearchWorker&) = delete;
  SearchWorker& operator=(const SearchWorker&) = delete;

  int threads() const { return static_cast<int>(helpers_.size()) + 1; }

  // Runs job(t) for every t in [0, n), n <= threads(): job(0) on the calling thread, job(t) on
  // helper t; returns when all are done. The jobs may not throw.
  void run(int n, const std::function<void(int)>& job) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      job_ = &job;
      jobs_ = n;
      pending_ = n - 1;
      ++generation_;
    }
    if (n > 1) wake_.notify_all();
    job(0);
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [this] { return pending_ <= 0; });
    job_ = nullptr;
  }

  // Runs `mine` on the calling thread and `theirs` on the first helper (or after `mine`, with
  // one thread); returns when both are done. Neither may throw.
  void run_both(const std::function<void()>& mine, const std::function<void()>& theirs) {
    if (threads() < 2) {
      mine();
      theirs();
      return;
    }
    run(2, [&](int t) { t == 0 ? mine() : theirs(); });
  }

 private:
  void loop(int index) {
    std::unique_lock<std::mutex> lock(mutex_);
    unsigned long long seen = 0;
    for (;;) {
      wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
      if (index >= jobs_) continue;
      const std::function<void(int)>* job = job_;
      lock.unlock();
      (*job)(index);
      lock.lock();
      if (--pending_ == 0) done_.notify_all();
    }
  }
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  const std::function<void(int)>* job_ = nullptr;
  int jobs_ = 0, pending_ = 0;
  unsigned long long generation_ = 0;
  bool stop_ = false;
  std::vector<std::thread> helpers_;  // last: started once the members above exist
};

// Runs `mine` here and `theirs` on the helper thread, returns when both are done and rethrows
// the first exception of either (neither may leave the other running on freed state).
inline void run_both(SearchWorker& worker, const std::function<void()>& mine, const std::function<void()>& theirs) {
  std::exception_ptr mine_error, their_error;
  auto guarded = [](const std::function<void()>& job, std::exception_ptr& error) {
    try {
      job();
    } catch (...) {
      error = std::current_exception();
    }
  };
  worker.run_both([&] { guarded(mine, mine_error); }, [&] { guarded(theirs, their_error); });
  if (mine_error) std::rethrow_exception(mine_error);
  if (their_error) std::rethrow_exception(their_error);
}

// A RunBoth (run_both.h) on `worker`'s helper thread through run_both() above; empty without a
// worker (one thread). `worker` must outlive the calls.
inline RunBoth on_helper(SearchWorker* worker) {
  if (!worker) return {};
  return [worker](const std::function<void()>& mine, const std::function<void()>& theirs) {
    run_both(*worker, mine, theirs);
  };
}

}  // namespace cf::detail
