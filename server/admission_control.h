#ifndef HPOSE_SERVER_ADMISSION_CONTROL_H_
#define HPOSE_SERVER_ADMISSION_CONTROL_H_

#include <cstdint>
#include <mutex>

namespace hpose::server {

// Bounds the Estimate calls a daemon holds at once, by count and by request bytes, so a flood
// of large requests is answered RESOURCE_EXHAUSTED at the door instead of being decoded, copied
// into clouds and queued until memory runs out. Thread-safe.
class AdmissionControl {
 public:
  // `max_calls` calls at most (>= 1) whose requests add up to `max_bytes` at most.
  AdmissionControl(int max_calls, std::uint64_t max_bytes);

  // Held while a call runs; gives its share back when destroyed.
  class Ticket {
   public:
    Ticket(Ticket&& other) noexcept : owner_(other.owner_), bytes_(other.bytes_) {
      other.owner_ = nullptr;
    }
    Ticket(const Ticket&) = delete;
    Ticket& operator=(const Ticket&) = delete;
    Ticket& operator=(Ticket&&) = delete;
    ~Ticket();
    bool admitted() const { return owner_ != nullptr; }

   private:
    friend class AdmissionControl;
    Ticket(AdmissionControl* owner, std::uint64_t bytes) : owner_(owner), bytes_(bytes) {}
    AdmissionControl* owner_;
    std::uint64_t bytes_;
  };

  // Admits a call of `bytes` request bytes; the ticket is not admitted() when `max_calls` calls
  // are running or the bytes would exceed `max_bytes` (the caller answers RESOURCE_EXHAUSTED).
  Ticket TryAdmit(std::uint64_t bytes);

  int max_calls() const { return max_calls_; }
  std::uint64_t max_bytes() const { return max_bytes_; }
  std::uint64_t rejected() const;  // calls refused so far.

 private:
  void Release(std::uint64_t bytes);

  const int max_calls_;
  const std::uint64_t max_bytes_;
  mutable std::mutex mu_;
  int calls_ = 0;
  std::uint64_t bytes_ = 0;
  std::uint64_t rejected_ = 0;
};

}  // namespace hpose::server

#endif  // HPOSE_SERVER_ADMISSION_CONTROL_H_
