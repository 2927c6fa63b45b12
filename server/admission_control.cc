#include "server/admission_control.h"

#include <cassert>

namespace hpose::server {

AdmissionControl::AdmissionControl(int max_calls, std::uint64_t max_bytes)
    : max_calls_(max_calls), max_bytes_(max_bytes) {
  assert(max_calls >= 1);
}

AdmissionControl::Ticket::~Ticket() {
  if (owner_ != nullptr) owner_->Release(bytes_);
}

AdmissionControl::Ticket AdmissionControl::TryAdmit(std::uint64_t bytes) {
  std::lock_guard<std::mutex> lock(mu_);
  if (calls_ >= max_calls_ || bytes > max_bytes_ - bytes_) {
    ++rejected_;
    return Ticket(nullptr, 0);
  }
  ++calls_;
  bytes_ += bytes;
  return Ticket(this, bytes);
}

std::uint64_t AdmissionControl::rejected() const {
  std::lock_guard<std::mutex> lock(mu_);
  return rejected_;
}

void AdmissionControl::Release(std::uint64_t bytes) {
  std::lock_guard<std::mutex> lock(mu_);
  --calls_;
  bytes_ -= bytes;
}

}  // namespace hpose::server
