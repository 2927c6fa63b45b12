#ifndef HPOSE_SERVER_PUBLISH_SIGNAL_H_
#define HPOSE_SERVER_PUBLISH_SIGNAL_H_

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>

namespace hpose::server {

// Wakes readers that wait on several pipelines at once (a stream of both estimators): every
// pipeline that publishes an estimate, or stops, calls Notify(); a reader remembers count()
// before looking at the pipelines and waits for it to change. Thread-safe.
class PublishSignal final {
 public:
  void Notify() {
    {
      std::lock_guard<std::mutex> lock(mu_);
      ++count_;
    }
    cv_.notify_all();
  }

  std::uint64_t count() const {
    std::lock_guard<std::mutex> lock(mu_);
    return count_;
  }

  // Waits until count() differs from `seen` or `deadline` passes; true when it changed.
  bool WaitChange(std::uint64_t seen, std::chrono::steady_clock::time_point deadline) const {
    std::unique_lock<std::mutex> lock(mu_);
    return cv_.wait_until(lock, deadline, [&] { return count_ != seen; });
  }

 private:
  mutable std::mutex mu_;
  mutable std::condition_variable cv_;
  std::uint64_t count_ = 0;
};

}  // namespace hpose::server

#endif  // HPOSE_SERVER_PUBLISH_SIGNAL_H_
