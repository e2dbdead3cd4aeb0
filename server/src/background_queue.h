// One background thread that runs tasks in the order they were queued: the coordinator's work that
// must not run under its lock nor hold up a request (writing a finished job's image, and then its
// webhook; denoising). Destruction runs what is queued (or drops what has not begun: OnStop), then stops.
#pragma once

#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>

namespace tessera::server {

class BackgroundQueue {
 public:
  /// What destruction does with tasks not yet begun.
  enum class OnStop { RunQueued, DropQueued };
  explicit BackgroundQueue(OnStop on_stop = OnStop::RunQueued) : on_stop_(on_stop), thread_([this] { run(); }) {}
  ~BackgroundQueue() {
    {
      std::lock_guard<std::mutex> lock(mu_);
      stopping_ = true;
      if (on_stop_ == OnStop::DropQueued) tasks_.clear();
    }
    cv_.notify_one();
    thread_.join();
  }
  BackgroundQueue(const BackgroundQueue&) = delete;
  BackgroundQueue& operator=(const BackgroundQueue&) = delete;

  void push(std::function<void()> task) {
    {
      std::lock_guard<std::mutex> lock(mu_);
      tasks_.push_back(std::move(task));
    }
    cv_.notify_one();
  }

 private:
  void run() {
    std::unique_lock<std::mutex> lock(mu_);
    for (;;) {
      cv_.wait(lock, [&] { return stopping_ || !tasks_.empty(); });
      if (tasks_.empty()) return;
      std::function<void()> task = std::move(tasks_.front());
      tasks_.pop_front();
      lock.unlock();
      task();  // (tasks catch their own errors)
      lock.lock();
    }
  }

  const OnStop on_stop_;
  std::mutex mu_;
  std::condition_variable cv_;
  std::deque<std::function<void()>> tasks_;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace tessera::server
