#include "server/elastic_task_queue.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <system_error>
#include <utility>

namespace hpose::server {

ElasticTaskQueue::ElasticTaskQueue(int min_threads, int max_threads)
    : max_threads_(std::max(1, std::max(min_threads, max_threads))) {
  const std::lock_guard<std::mutex> lock(mutex_);
  for (int i = 0; i < std::clamp(min_threads, 1, max_threads_); ++i) StartThreadLocked();
}

ElasticTaskQueue::~ElasticTaskQueue() { Shutdown(); }

void ElasticTaskQueue::Enqueue(std::function<void()> job) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (shutdown_) return;
    jobs_.push_back(std::move(job));
    // Every queued job beyond the idle threads would wait: start a thread for it.
    if (static_cast<int>(jobs_.size()) > idle_ &&
        static_cast<int>(threads_.size()) < max_threads_) {
      StartThreadLocked();
    }
  }
  wake_.notify_one();
}

void ElasticTaskQueue::Shutdown() {
  std::vector<std::thread> threads;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    shutdown_ = true;
    threads.swap(threads_);
  }
  wake_.notify_all();
  for (std::thread& t : threads) t.join();
}

int ElasticTaskQueue::threads() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<int>(threads_.size());
}

void ElasticTaskQueue::StartThreadLocked() {
  try {
    threads_.emplace_back([this] { Work(); });
  } catch (const std::system_error& e) {
    // No thread to be had (a task limit such as systemd's TasksMax reached, or out of memory):
    // the job waits for a running thread instead of the exception ending the daemon.
    if (!warned_) {
      warned_ = true;
      spdlog::warn(
          "web view: cannot start another worker thread ({}); requests wait for the {} running",
          e.what(), threads_.size());
    }
  }
}

void ElasticTaskQueue::Work() {
  for (;;) {
    std::function<void()> job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      ++idle_;
      wake_.wait(lock, [this] { return shutdown_ || !jobs_.empty(); });
      --idle_;
      if (jobs_.empty()) return;  // shut down with nothing left to run.
      job = std::move(jobs_.front());
      jobs_.pop_front();
    }
    job();
  }
}

}  // namespace hpose::server
