#include "core/common/task_pool.h"

#include <algorithm>

#if defined(__linux__)
#include <sched.h>
#endif

namespace hpose {

TaskPool::TaskPool(int threads) {
  for (int i = 1; i < std::max(threads, 1); ++i) workers_.emplace_back([this] { WorkerLoop(); });
}

TaskPool::~TaskPool() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    stop_ = true;
  }
  work_cv_.notify_all();
  for (std::thread& t : workers_) t.join();
}

int TaskPool::Resolve(int requested) {
  if (requested > 0) return requested;
  return UsableCores();
}

int TaskPool::UsableCores() {
#if defined(__linux__)
  // The CPUs this process may run on (taskset, cpusets), not every CPU of the machine: more
  // threads than that only take turns on the same cores.
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) == 0) return std::max(1, CPU_COUNT(&set));
#endif
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

void TaskPool::ParallelFor(int n, const std::function<void(int)>& fn) {
  if (n <= 0) return;
  if (workers_.empty() || n == 1) {
    for (int i = 0; i < n; ++i) fn(i);
    return;
  }
  std::lock_guard<std::mutex> loop(loop_mu_);
  {
    std::lock_guard<std::mutex> lock(mu_);
    fn_ = &fn;
    n_ = n;
    next_ = 0;
    running_ = 0;
    ++generation_;
  }
  work_cv_.notify_all();
  RunItems();
  std::unique_lock<std::mutex> lock(mu_);
  done_cv_.wait(lock, [this] { return next_ >= n_ && running_ == 0; });
  fn_ = nullptr;
}

void TaskPool::RunItems() {
  std::unique_lock<std::mutex> lock(mu_);
  while (fn_ != nullptr && next_ < n_) {
    const int item = next_++;
    ++running_;
    const std::function<void(int)>& fn = *fn_;
    lock.unlock();
    fn(item);
    lock.lock();
    --running_;
  }
  if (next_ >= n_ && running_ == 0) done_cv_.notify_all();
}

void TaskPool::WorkerLoop() {
  long seen = 0;
  std::unique_lock<std::mutex> lock(mu_);
  for (;;) {
    work_cv_.wait(lock, [&] { return stop_ || (generation_ != seen && fn_ != nullptr); });
    if (stop_) return;
    seen = generation_;
    lock.unlock();
    RunItems();
    lock.lock();
  }
}

}  // namespace hpose
