#ifndef HPOSE_SERVER_POSE_PIPELINE_H_
#define HPOSE_SERVER_POSE_PIPELINE_H_

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "core/common/status.h"
#include "core/search/estimator.h"
#include "server/daemon_config.h"
#include "server/frame_queue.h"
#include "server/frame_source.h"
#include "server/pipeline_stats.h"
#include "server/publish_order.h"
#include "server/publish_signal.h"

namespace hpose {
struct SimulatedFrame;
}

namespace hpose::server {

enum class SourceState { kNone, kStarting, kRunning, kReconnecting, kFinished, kFailed };

const char* SourceStateName(SourceState state);

// Logs a source's change of state, one line (info: opened, reconnected, finished; warn: lost,
// failed); nothing when `from` equals `to`. `what` names the source ("stereo source DIR").
void LogSourceStateChange(const std::string& what, SourceState from, SourceState to,
                          const std::string& reason);

// Whether an estimate published `age_s` ago by a source in `state` is stale, and why: the
// source is not running ("<source_name> finished: <state_reason>"), or nothing newer came for
// longer than `stale_after_s` ("no newer <estimate_name> for 2.31 s"). Clears `reason` when
// the estimate is fresh.
bool DescribeStaleness(SourceState state, const std::string& state_reason, double age_s,
                       double stale_after_s, const std::string& source_name,
                       const std::string& estimate_name, std::string* reason);

// The outcome of one source frame, as published to readers.
struct PublishedEstimate {
  std::uint64_t publish_id = 0;  // 1, 2, ... in publishing order.
  std::uint64_t sequence = 0;    // the frame's sequence number from the source.
  double source_time_s = 0.0;
  std::chrono::system_clock::time_point received;
  std::chrono::steady_clock::time_point received_steady;  // the same moment, for latency_s.
  std::chrono::steady_clock::time_point published;
  std::chrono::system_clock::time_point published_wall;
  std::uint64_t source_epoch = 0;
  std::string origin;
  // The input frame, for the publish observer (web view); null once published to readers is
  // all that matters.
  std::shared_ptr<const Frame> frame;
  bool ok = false;
  Estimate estimate;       // when ok.
  Error error;             // when !ok (e.g. no floor in this frame).
  double queue_s = 0.0;    // waiting in the frame queue.
  double latency_s = 0.0;  // arrival to publication.
};

// Counters and rates of the pipeline, for GetStatus.
struct PipelineStatus {
  SourceState state = SourceState::kNone;
  std::string reason;  // why the state is not kRunning.
  std::string kind;
  std::string description;
  std::uint64_t frames_in = 0;
  std::uint64_t frames_dropped = 0;
  std::uint64_t frames_estimated = 0;
  std::uint64_t frames_failed = 0;
  std::uint64_t reconnects = 0;
  // The size and camera of the depth frames read last (has_camera), or that the source gives
  // point clouds; neither before the first frame. For the stereo source: the size of the pairs
  // read and the calibration's left camera.
  bool has_camera = false;
  Intrinsics camera;
  bool point_clouds = false;
  double input_rate_hz = 0.0;  // over the last few seconds.
  double estimate_rate_hz = 0.0;
  double latency_median_s = 0.0;  // over the last 256 published frames.
  double latency_p99_s = 0.0;
  double latency_last_s = 0.0;
  std::uint32_t latency_samples = 0;
  bool has_floor = false;
  FloorEstimate last_floor;
  // SourceConfig::warm_up: every estimation thread has estimated the synthetic frame, the
  // slowest taking warm_up_ms.
  bool warmed_up = false;
  double warm_up_ms = 0.0;
};

// A status's rates and latency from the pipeline's window (depth and stereo pipelines alike).
void SetRatesAndLatency(const StatsSnapshot& stats, PipelineStatus* status);

// Reads the daemon's source on a capture thread into a bounded FrameQueue and estimates on one
// estimation thread per estimator (each on its own frame, so with two estimators a frame may
// take up to two frame periods and the daemon still keeps up); the newest result is published
// for GetLatest / StreamPoses, always in frame order (PublishOrder: a recording replayed as
// fast as possible publishes every frame in order; a live or real-time source never publishes
// an older frame after a newer one and counts such a frame as dropped). A live device that
// fails is closed and reopened with exponential back-off while readers keep being served; a
// recording that ends leaves its last estimate in place (then reported stale).
class PosePipeline {
 public:
  // `source` may be null (no source: state kNone). Each estimator is used by its own estimation
  // thread only (at least one when there is a source). `signal`, when not null, is notified
  // after every publication and on Stop(); it must outlive the pipeline.
  PosePipeline(std::unique_ptr<FrameSource> source,
               std::vector<std::unique_ptr<Estimator>> estimators, SourceConfig config,
               PublishSignal* signal = nullptr);
  // One estimation thread.
  PosePipeline(std::unique_ptr<FrameSource> source, std::unique_ptr<Estimator> estimator,
               SourceConfig config, PublishSignal* signal = nullptr);
  ~PosePipeline();

  PosePipeline(const PosePipeline&) = delete;
  PosePipeline& operator=(const PosePipeline&) = delete;

  // Called on the estimation thread after each publication, with the frame it came from
  // (metrics, the web view). Set before Start(); must be cheap and must not call back into the
  // pipeline.
  using PublishObserver = std::function<void(const PublishedEstimate&, const Frame&)>;
  void SetPublishObserver(PublishObserver observer) { observer_ = std::move(observer); }

  // The source is opened once the estimation threads have warmed up (SourceConfig::warm_up) and,
  // when valid, `other_warm_up` is ready (the daemon's other estimators warming up, so that they
  // do not compete with the first frames).
  void Start(std::shared_future<void> other_warm_up = {});
  // Stops both threads (waits for a blocked source read to return). Idempotent.
  void Stop();

  // The newest published estimate, or null before the first.
  std::shared_ptr<const PublishedEstimate> Latest() const;
  // Waits until an estimate with publish_id > `after` exists, `deadline` passes, the pipeline
  // has ended or stops; returns the newest (possibly not newer, or null).
  std::shared_ptr<const PublishedEstimate> WaitNewer(
      std::uint64_t after, std::chrono::steady_clock::time_point deadline) const;
  // True once the source has ended (finished or failed) and the estimate of every frame it
  // delivered has been published: no estimate will follow. A live source that is lost
  // reconnects instead and never ends; a looping recording never ends.
  bool Ended() const;

  // True (with the reason) when `e` is not fresh: the source is not running, or `e` is older
  // than stale_after_s.
  bool IsStale(const PublishedEstimate& e, std::string* reason) const;

  PipelineStatus Status() const;
  bool has_source() const { return source_ != nullptr; }

 private:
  // Runs CaptureFrames, then tells the estimation threads that no frame will follow.
  void CaptureLoop();
  void CaptureFrames();
  void EstimateLoop(Estimator* estimator);
  // Estimates the warm-up frame (WarmUpFrame) with `estimator` (SourceConfig::warm_up) and
  // counts it done.
  void WarmUp(Estimator* estimator);
  // Waits until every estimation thread has warmed up, and other_warm_up_; false when stopping.
  bool WaitForWarmUp();
  // Hands the result of frame `ticket` to publish_order_ and publishes what it releases.
  void Publish(std::uint64_t ticket, std::shared_ptr<PublishedEstimate> result);
  void SetState(SourceState state, std::string reason);
  // LogSourceStateChange for this pipeline's source. Called with mu_ held.
  void LogStateChange(SourceState from, SourceState to, const std::string& reason) const;
  // Sleeps up to `d` unless stopping; false when stopping.
  bool SleepFor(std::chrono::duration<double> d);
  bool OpenWithBackoff();

  std::unique_ptr<FrameSource> source_;
  std::vector<std::unique_ptr<Estimator>> estimators_;
  const SourceConfig config_;
  PublishSignal* const signal_;
  PublishObserver observer_;
  FrameQueue queue_;

  std::thread capture_thread_;
  std::vector<std::thread> estimate_threads_;
  // Taking a frame from the queue and its ticket happen together under this lock, so tickets
  // follow the frames' order.
  std::mutex take_mu_;
  std::atomic<bool> stopping_{false};
  // Set once the capture thread has pushed its last frame.
  std::atomic<bool> capture_done_{false};
  bool started_ = false;
  std::shared_future<void> other_warm_up_;  // set by Start().

  mutable std::mutex mu_;  // guards everything below.
  mutable std::condition_variable published_cv_;
  std::condition_variable stop_cv_;
  SourceState state_ = SourceState::kNone;
  std::string reason_;
  std::shared_ptr<const PublishedEstimate> latest_;
  // Tickets are taken under take_mu_ and handed in under mu_.
  PublishOrder<std::shared_ptr<PublishedEstimate>> publish_order_;
  std::uint64_t next_publish_id_ = 1;
  int estimators_running_ = 0;
  bool ended_ = false;
  std::uint64_t frames_in_ = 0;
  std::uint64_t frames_dropped_ = 0;
  std::uint64_t frames_estimated_ = 0;
  std::uint64_t frames_failed_ = 0;
  std::uint64_t reconnects_ = 0;
  // What the frames read last rest on (PipelineStatus's fields of the same names).
  bool has_camera_ = false;
  Intrinsics camera_;
  bool point_clouds_ = false;
  PipelineStats stats_;
  bool has_floor_ = false;
  FloorEstimate last_floor_;
  int warm_ups_pending_ = 0;
  bool warmed_up_ = false;
  double warm_up_ms_ = 0.0;  // the slowest estimation thread's.
};

}  // namespace hpose::server

#endif  // HPOSE_SERVER_POSE_PIPELINE_H_
