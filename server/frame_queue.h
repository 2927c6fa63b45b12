#ifndef HPOSE_SERVER_FRAME_QUEUE_H_
#define HPOSE_SERVER_FRAME_QUEUE_H_

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <mutex>
#include <optional>
#include <utility>

#include "server/frame.h"

namespace hpose::server {

// A bounded FIFO of frames between the capture and the estimation threads. When full, Push
// either drops the oldest frame (live sources: the newest frame matters most) or waits for room
// (recordings replayed as fast as possible: nothing is lost). Thread-safe.
class FrameQueue {
 public:
  explicit FrameQueue(size_t capacity) : capacity_(capacity < 1 ? 1 : capacity) {}

  // Returns the number of frames dropped to make room (0 or 1). With `block_when_full`, waits
  // until there is room or the queue is closed (the frame is then discarded, returns 0).
  size_t Push(Frame frame, bool block_when_full) {
    std::unique_lock<std::mutex> lock(mu_);
    size_t dropped = 0;
    if (block_when_full) {
      not_full_.wait(lock, [this] { return closed_ || frames_.size() < capacity_; });
      if (closed_) return 0;
    } else if (frames_.size() >= capacity_) {
      frames_.pop_front();
      dropped = 1;
    }
    frames_.push_back(std::move(frame));
    not_empty_.notify_one();
    return dropped;
  }

  // Waits up to `timeout` for a frame; empty when none arrived or the queue is closed.
  std::optional<Frame> Pop(std::chrono::milliseconds timeout) {
    std::unique_lock<std::mutex> lock(mu_);
    not_empty_.wait_for(lock, timeout, [this] { return closed_ || !frames_.empty(); });
    if (frames_.empty()) return std::nullopt;
    Frame f = std::move(frames_.front());
    frames_.pop_front();
    not_full_.notify_one();
    return f;
  }

  // Wakes every waiter; later pushes are discarded.
  void Close() {
    std::lock_guard<std::mutex> lock(mu_);
    closed_ = true;
    not_empty_.notify_all();
    not_full_.notify_all();
  }

  size_t size() const {
    std::lock_guard<std::mutex> lock(mu_);
    return frames_.size();
  }

 private:
  const size_t capacity_;
  mutable std::mutex mu_;
  std::condition_variable not_empty_;
  std::condition_variable not_full_;
  std::deque<Frame> frames_;
  bool closed_ = false;
};

}  // namespace hpose::server

#endif  // HPOSE_SERVER_FRAME_QUEUE_H_
