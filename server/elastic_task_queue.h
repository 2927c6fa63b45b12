#ifndef HPOSE_SERVER_ELASTIC_TASK_QUEUE_H_
#define HPOSE_SERVER_ELASTIC_TASK_QUEUE_H_

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace hpose::server {

// The web view's workers: a job runs at once on an idle thread, or on a new one while there are
// fewer than `max_threads`; only beyond that does it wait. A fixed pool let a few connections
// that never finish their request (each holds a worker until the read times out) delay every
// other request, /healthz included, by seconds. Threads once started stay until Shutdown (an
// idle one costs its stack's reserved address space, little memory). When no thread can be
// started (a task limit), jobs wait for the running ones.
class ElasticTaskQueue {
 public:
  ElasticTaskQueue(int min_threads, int max_threads);
  ~ElasticTaskQueue();
  ElasticTaskQueue(const ElasticTaskQueue&) = delete;
  ElasticTaskQueue& operator=(const ElasticTaskQueue&) = delete;

  void Enqueue(std::function<void()> job);
  // Runs the jobs already queued, then joins every thread. Later Enqueue calls are dropped.
  void Shutdown();

  // Threads started and not yet joined (0 after Shutdown).
  int threads() const;

 private:
  void StartThreadLocked();
  void Work();

  const int max_threads_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::function<void()>> jobs_;
  std::vector<std::thread> threads_;
  int idle_ = 0;         // threads waiting for a job.
  bool warned_ = false;  // a thread could not be started (logged once).
  bool shutdown_ = false;
};

}  // namespace hpose::server

#endif  // HPOSE_SERVER_ELASTIC_TASK_QUEUE_H_
