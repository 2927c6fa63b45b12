#include "server/estimate_worker.h"

#include <utility>

namespace hpose::server {

EstimateWorker::EstimateWorker() : thread_([this] { Loop(); }) {}

EstimateWorker::~EstimateWorker() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    stopping_ = true;
  }
  cv_.notify_all();
  thread_.join();
}

void EstimateWorker::Run(const std::function<void()>& job) {
  std::unique_lock<std::mutex> lock(mu_);
  job_ = &job;
  cv_.notify_all();
  cv_.wait(lock, [this] { return job_ == nullptr; });
  if (thrown_) std::rethrow_exception(std::exchange(thrown_, nullptr));
}

void EstimateWorker::Loop() {
  std::unique_lock<std::mutex> lock(mu_);
  for (;;) {
    cv_.wait(lock, [this] { return stopping_ || job_ != nullptr; });
    if (job_ == nullptr) return;  // stopping, nothing left to run.
    const std::function<void()>* job = job_;
    lock.unlock();
    std::exception_ptr thrown;
    try {
      (*job)();
    } catch (...) {
      thrown = std::current_exception();  // the caller's, as if it had run the job itself.
    }
    lock.lock();
    thrown_ = thrown;
    job_ = nullptr;
    cv_.notify_all();
  }
}

}  // namespace hpose::server
