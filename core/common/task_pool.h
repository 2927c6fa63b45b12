#ifndef HPOSE_CORE_COMMON_TASK_POOL_H_
#define HPOSE_CORE_COMMON_TASK_POOL_H_

#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace hpose {

// A fixed set of worker threads for fork-join loops: ParallelFor(n, fn) runs fn(0) .. fn(n - 1),
// each exactly once, on the workers and the calling thread, and returns when all have
// returned. With one thread (or n <= 1) everything runs on the caller, in order. One loop at a
// time: concurrent ParallelFor calls on one pool take turns.
class TaskPool {
 public:
  // `threads` >= 1 including the caller: threads - 1 workers are started.
  explicit TaskPool(int threads);
  ~TaskPool();
  TaskPool(const TaskPool&) = delete;
  TaskPool& operator=(const TaskPool&) = delete;

  void ParallelFor(int n, const std::function<void(int)>& fn);
  int threads() const { return static_cast<int>(workers_.size()) + 1; }

  // `requested` threads, or one per usable core when 0 (at least 1).
  static int Resolve(int requested);
  // The cores this process may run on (its CPU affinity on Linux), at least 1.
  static int UsableCores();

 private:
  void WorkerLoop();
  // Claims and runs items of the current loop until none are left.
  void RunItems();

  std::vector<std::thread> workers_;
  std::mutex loop_mu_;  // one ParallelFor at a time.
  std::mutex mu_;
  std::condition_variable work_cv_;
  std::condition_variable done_cv_;
  const std::function<void(int)>* fn_ = nullptr;
  int n_ = 0;
  int next_ = 0;     // next item to claim.
  int running_ = 0;  // items claimed and not finished.
  long generation_ = 0;
  bool stop_ = false;
};

}  // namespace hpose

#endif  // HPOSE_CORE_COMMON_TASK_POOL_H_
