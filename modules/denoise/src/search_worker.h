#pragma once
// Internal to the denoise module: one persistent helper thread that runs a job while the caller
// runs another (two independent loop searches at once); no thread is started per job.
#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>

namespace cf::detail {

class SearchWorker {
 public:
  SearchWorker() : thread_([this] { loop(); }) {}
  ~SearchWorker() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    thread_.join();
  }
  SearchWorker(const SearchWorker&) = delete;
  SearchWorker& operator=(const SearchWorker&) = delete;

  // Runs `mine` on the calling thread and `theirs` on the helper; returns when both are done.
  // Neither job may throw.
  void run_both(const std::function<void()>& mine, const std::function<void()>& theirs) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      job_ = &theirs;
    }
    wake_.notify_all();
    mine();
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [this] { return job_ == nullptr; });
  }

 private:
  void loop() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      wake_.wait(lock, [this] { return stop_ || job_ != nullptr; });
      if (stop_) return;
      const std::function<void()>* job = job_;
      lock.unlock();
      (*job)();
      lock.lock();
      job_ = nullptr;
      done_.notify_all();
    }
  }
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  const std::function<void()>* job_ = nullptr;
  bool stop_ = false;
  std::thread thread_;  // last: started once the members above exist
};

}  // namespace cf::detail
