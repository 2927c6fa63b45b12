#ifndef HPOSE_SERVER_STEREO_PIPELINE_H_
#define HPOSE_SERVER_STEREO_PIPELINE_H_

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "core/common/status.h"
#include "core/stereo/stereo_estimator.h"
#include "core/stereo/stereo_frame_result.h"
#include "core/stereo/stereo_sequence.h"
#include "core/stereo/stereo_tracker.h"
#include "server/daemon_config.h"
#include "server/pipeline_stats.h"
#include "server/pose_pipeline.h"
#include "server/publish_signal.h"

namespace hpose::server {

// The outcome of one stereo pair of the daemon's stereo source, as published to readers.
struct PublishedStereoEstimate {
  std::uint64_t publish_id = 0;  // 1, 2, ... in publishing order.
  std::uint64_t sequence = 0;    // 1, 2, ... per pair read, counting loops and skipped pairs.
  double source_time_s = 0.0;    // the pair's timestamp in the sequence, seconds.
  std::chrono::system_clock::time_point received;
  std::chrono::steady_clock::time_point published;
  std::chrono::system_clock::time_point published_wall;
  std::uint64_t source_epoch = 0;  // +1 each time the sequence loops back to its first pair.
  std::string origin;              // the left image's file name.
  // True when the pair was read and processed; `frame` and `track` are then valid (the frame may
  // still have no robot pose: see frame.status). False: `error` says why (unreadable image,
  // images of different sizes, ...).
  bool ok = false;
  StereoFrameResult frame;
  StereoTrackState track;  // the tracker after this frame (world frame).
  Error error;
  double process_s = 0.0;  // StereoEstimator::Process time.
  double latency_s = 0.0;  // reading the pair to publication.
};

// Plays a StereoSequence (a directory of left/right pairs) at its timestamps (or as fast as
// possible), runs the stereo-marker estimator and the StereoTracker on every pair on one thread
// and publishes the newest result for GetLatest / StreamPoses. When processing falls behind the
// recorded rate, pairs whose successor is already due are skipped (counted as dropped). Looping
// resets the tracker. A pair that cannot be read is published with its error and the sequence
// goes on; after 100 such pairs in a row the source is reported failed.
class StereoPipeline final {
 public:
  // `estimator` must outlive the pipeline (it is shared with EstimateStereo calls; Process is
  // const). `signal` (may be null) is notified after every publication and on Stop().
  StereoPipeline(StereoSequence sequence, const StereoEstimator* estimator, StereoConfig config,
                 PublishSignal* signal = nullptr);
  ~StereoPipeline();

  StereoPipeline(const StereoPipeline&) = delete;
  StereoPipeline& operator=(const StereoPipeline&) = delete;

  void Start();
  void Stop();  // Idempotent.

  // The newest published estimate, or null before the first.
  std::shared_ptr<const PublishedStereoEstimate> Latest() const;
  // Waits until an estimate with publish_id > `after` exists, `deadline` passes or the pipeline
  // stops; returns the newest (possibly not newer, or null).
  std::shared_ptr<const PublishedStereoEstimate> WaitNewer(
      std::uint64_t after, std::chrono::steady_clock::time_point deadline) const;
  // True once the sequence has ended (finished or failed) after publishing its last pair: no
  // estimate will follow.
  bool Ended() const;
  // True (with the reason) when `e` is not fresh: the source is not running, or `e` is older
  // than stale_after_s.
  bool IsStale(const PublishedStereoEstimate& e, std::string* reason) const;

  // Counters as for the depth source; kind "stereo-dir". frames_estimated counts pairs that
  // gave a robot pose, frames_failed those that did not. has_floor is always false.
  PipelineStatus Status() const;

 private:
  void Run();
  void Publish(std::shared_ptr<PublishedStereoEstimate> e, bool robot_found);
  bool SleepUntil(std::chrono::steady_clock::time_point t);
  void SetState(SourceState state, std::string reason);
  bool EndedLocked() const;  // Ended() with mu_ held.
  // Records the size of the pair read (its left image's) with the calibration's left camera,
  // for Status().
  void NoteCamera(int width, int height);

  const StereoSequence sequence_;
  const StereoEstimator* const estimator_;
  const StereoConfig config_;
  PublishSignal* const signal_;
  StereoTracker tracker_;  // run thread only.

  std::thread thread_;
  std::atomic<bool> stopping_{false};
  bool started_ = false;

  mutable std::mutex mu_;  // guards everything below.
  mutable std::condition_variable published_cv_;
  std::condition_variable stop_cv_;
  SourceState state_ = SourceState::kStarting;
  std::string reason_ = "starting";
  std::shared_ptr<const PublishedStereoEstimate> latest_;
  std::uint64_t next_publish_id_ = 1;
  std::uint64_t frames_in_ = 0;
  std::uint64_t frames_dropped_ = 0;
  std::uint64_t frames_estimated_ = 0;
  std::uint64_t frames_failed_ = 0;
  // The pairs' size and the left camera of the calibration, from the first pair read on.
  bool has_camera_ = false;
  Intrinsics camera_;
  PipelineStats stats_;
};

}  // namespace hpose::server

#endif  // HPOSE_SERVER_STEREO_PIPELINE_H_
