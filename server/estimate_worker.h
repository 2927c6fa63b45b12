#ifndef HPOSE_SERVER_ESTIMATE_WORKER_H_
#define HPOSE_SERVER_ESTIMATE_WORKER_H_

#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

namespace hpose::server {

// A thread of its own for one caller at a time: Run hands it a job and returns when the job is
// done. An estimate keeps buffers per thread (scratch that grows to a frame's size, the
// allocator's arena); run on the same worker call after call, it finds them grown instead of
// paying for their first use on whichever thread the call arrived on.
class EstimateWorker {
 public:
  EstimateWorker();
  ~EstimateWorker();  // waits for a running job.

  EstimateWorker(const EstimateWorker&) = delete;
  EstimateWorker& operator=(const EstimateWorker&) = delete;

  // Runs `job` on the worker's thread; what it throws is thrown here. One caller at a time.
  void Run(const std::function<void()>& job);

 private:
  void Loop();

  std::mutex mu_;
  std::condition_variable cv_;
  const std::function<void()>* job_ = nullptr;  // the job to run; null once done.
  std::exception_ptr thrown_;                   // by the job just run.
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace hpose::server

#endif  // HPOSE_SERVER_ESTIMATE_WORKER_H_
