#include "server/pose_pipeline.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include <spdlog/spdlog.h>

#include "core/search/pose_tracker.h"
#include "core/sim/frame_simulator.h"
#include "server/pipeline_stats.h"
#include "server/warm_up_frame.h"

namespace hpose::server {

namespace {

using Clock = std::chrono::steady_clock;

constexpr int kMaxConsecutiveBadFrames = 100;

}  // namespace

const char* SourceStateName(SourceState state) {
  switch (state) {
    case SourceState::kNone:
      return "none";
    case SourceState::kStarting:
      return "starting";
    case SourceState::kRunning:
      return "running";
    case SourceState::kReconnecting:
      return "reconnecting";
    case SourceState::kFinished:
      return "finished";
    case SourceState::kFailed:
      return "failed";
  }
  return "unknown";
}

bool DescribeStaleness(SourceState state, const std::string& state_reason, double age_s,
                       double stale_after_s, const std::string& source_name,
                       const std::string& estimate_name, std::string* reason) {
  if (state != SourceState::kRunning) {
    *reason = source_name + " " + SourceStateName(state) +
              (state_reason.empty() ? "" : ": " + state_reason);
    return true;
  }
  if (age_s > stale_after_s) {
    char age[32];
    std::snprintf(age, sizeof(age), "%.2f s", age_s);
    *reason = "no newer " + estimate_name + " for " + age;
    return true;
  }
  reason->clear();
  return false;
}

namespace {

// Recordings replayed as fast as possible lose no frame: every result is published, in order.
// Live and real-time sources want the newest pose only.
PublishOrder<std::shared_ptr<PublishedEstimate>>::Policy OrderPolicy(const FrameSource* source,
                                                                     const SourceConfig& config) {
  using Order = PublishOrder<std::shared_ptr<PublishedEstimate>>;
  const bool newest_only = source != nullptr && (source->live() || config.realtime);
  return newest_only ? Order::Policy::kNewestOnly : Order::Policy::kInOrder;
}

std::vector<std::unique_ptr<Estimator>> OneEstimator(std::unique_ptr<Estimator> estimator) {
  std::vector<std::unique_ptr<Estimator>> v;
  if (estimator) v.push_back(std::move(estimator));
  return v;
}

}  // namespace

PosePipeline::PosePipeline(std::unique_ptr<FrameSource> source,
                           std::vector<std::unique_ptr<Estimator>> estimators, SourceConfig config,
                           PublishSignal* signal)
    : source_(std::move(source)),
      estimators_(std::move(estimators)),
      config_(std::move(config)),
      signal_(signal),
      queue_(static_cast<size_t>(std::max(1, config_.queue_capacity))),
      publish_order_(OrderPolicy(source_.get(), config_)) {
  state_ = source_ ? SourceState::kStarting : SourceState::kNone;
  reason_ = source_ ? "opening the source" : "no source configured";
}

PosePipeline::PosePipeline(std::unique_ptr<FrameSource> source,
                           std::unique_ptr<Estimator> estimator, SourceConfig config,
                           PublishSignal* signal)
    : PosePipeline(std::move(source), OneEstimator(std::move(estimator)), std::move(config),
                   signal) {}

PosePipeline::~PosePipeline() { Stop(); }

void PosePipeline::Start(std::shared_future<void> other_warm_up) {
  if (started_ || !source_) return;
  started_ = true;
  other_warm_up_ = std::move(other_warm_up);
  {
    std::lock_guard<std::mutex> lock(mu_);
    estimators_running_ = static_cast<int>(estimators_.size());
    warm_ups_pending_ = config_.warm_up ? static_cast<int>(estimators_.size()) : 0;
  }
  capture_thread_ = std::thread([this] { CaptureLoop(); });
  for (const std::unique_ptr<Estimator>& e : estimators_) {
    estimate_threads_.emplace_back([this, estimator = e.get()] { EstimateLoop(estimator); });
  }
}

void PosePipeline::Stop() {
  if (stopping_.exchange(true)) return;
  {
    std::lock_guard<std::mutex> lock(mu_);
    stop_cv_.notify_all();
    published_cv_.notify_all();
  }
  if (signal_ != nullptr) signal_->Notify();
  queue_.Close();
  if (capture_thread_.joinable()) capture_thread_.join();
  for (std::thread& t : estimate_threads_) {
    if (t.joinable()) t.join();
  }
  if (source_) source_->Close();
}

void LogSourceStateChange(const std::string& what, SourceState from, SourceState to,
                          const std::string& reason) {
  if (from == to) return;
  if (to == SourceState::kRunning) {
    spdlog::info("{} {}", what, from == SourceState::kReconnecting ? "reconnected" : "opened");
  } else if (to == SourceState::kReconnecting || to == SourceState::kFailed) {
    spdlog::warn("{} {} ({})", what, to == SourceState::kFailed ? "failed" : "lost", reason);
  } else {
    spdlog::info("{} {}{}", what, SourceStateName(to), reason.empty() ? "" : " (" + reason + ")");
  }
}

void PosePipeline::LogStateChange(SourceState from, SourceState to,
                                  const std::string& reason) const {
  LogSourceStateChange("source " + (source_ ? source_->description() : std::string("(none)")), from,
                       to, reason);
}

void PosePipeline::SetState(SourceState state, std::string reason) {
  std::lock_guard<std::mutex> lock(mu_);
  LogStateChange(state_, state, reason);
  state_ = state;
  reason_ = std::move(reason);
}

bool PosePipeline::SleepFor(std::chrono::duration<double> d) {
  std::unique_lock<std::mutex> lock(mu_);
  stop_cv_.wait_for(lock, d, [this] { return stopping_.load(); });
  return !stopping_.load();
}

bool PosePipeline::OpenWithBackoff() {
  double backoff = config_.reconnect_initial_backoff_s;
  while (!stopping_.load()) {
    hpose::Status status = source_->Open();
    if (status.ok()) return true;
    if (!source_->live()) {
      SetState(SourceState::kFailed, status.error().message);
      return false;
    }
    {
      std::lock_guard<std::mutex> lock(mu_);
      char buf[64];
      std::snprintf(buf, sizeof(buf), "; retrying in %.1f s", backoff);
      LogStateChange(state_, SourceState::kReconnecting, status.error().message);
      state_ = SourceState::kReconnecting;
      reason_ = status.error().message + buf;
    }
    if (!SleepFor(std::chrono::duration<double>(backoff))) return false;
    backoff = std::min(backoff * 2.0, config_.reconnect_max_backoff_s);
  }
  return false;
}

void PosePipeline::CaptureLoop() {
  CaptureFrames();
  capture_done_.store(true);
  // Frames still queued are estimated; an estimation thread that finds the queue empty stops.
  queue_.Close();
}

namespace {

// Whether two frames rest on the same geometry: both clouds, or the same size and camera.
bool SameGeometry(const Frame& a, const Frame& b) {
  if (a.is_cloud || b.is_cloud) return a.is_cloud == b.is_cloud;
  const Intrinsics& k = a.intrinsics;
  const Intrinsics& l = b.intrinsics;
  return k.width == l.width && k.height == l.height && k.fx == l.fx && k.fy == l.fy &&
         k.cx == l.cx && k.cy == l.cy;
}

// What a frame's estimate rests on: its size and camera, or that it is a cloud.
std::string FrameGeometry(const Frame& frame) {
  if (frame.is_cloud) return "point clouds in the sensor frame";
  const Intrinsics& k = frame.intrinsics;
  char text[160];
  std::snprintf(text, sizeof(text), "%dx%d depth frames, fx %.1f fy %.1f cx %.1f cy %.1f", k.width,
                k.height, k.fx, k.fy, k.cx, k.cy);
  return text;
}

}  // namespace

void PosePipeline::CaptureFrames() {
  // Opened once the estimators have warmed up: a recording played at its recorded rate (or a
  // device's stream) starts then, with no frame due before the estimators can take it.
  if (!WaitForWarmUp()) return;
  if (!OpenWithBackoff()) return;
  SetState(SourceState::kRunning, "");
  const bool drop_oldest = source_->live() || config_.realtime;
  int consecutive_bad = 0;
  // Unreadable frames are logged, at most one line a second (with how many went unsaid).
  Clock::time_point last_bad_log{};
  int bad_unlogged = 0;
  // The frames' size and camera, logged for the first frame and whenever they change (a device
  // in another mode after a reconnection): what the estimates rest on, for a person to check.
  bool geometry_logged = false;
  Frame geometry;  // its is_cloud and intrinsics only.
  while (!stopping_.load()) {
    Result<Frame> frame = source_->Next();
    if (stopping_.load()) break;
    if (frame.ok()) {
      consecutive_bad = 0;
      if (!geometry_logged || !SameGeometry(geometry, *frame)) {
        geometry_logged = true;
        geometry.is_cloud = frame->is_cloud;
        geometry.intrinsics = frame->intrinsics;
        {
          std::lock_guard<std::mutex> lock(mu_);
          point_clouds_ = frame->is_cloud;
          has_camera_ = !frame->is_cloud;
          camera_ = frame->intrinsics;
        }
        spdlog::info("source {}: {}", source_->description(), FrameGeometry(*frame));
      }
      {
        std::lock_guard<std::mutex> lock(mu_);
        ++frames_in_;
        stats_.RecordInput(Clock::now());
      }
      const size_t dropped = queue_.Push(std::move(*frame), !drop_oldest);
      if (dropped > 0) {
        std::lock_guard<std::mutex> lock(mu_);
        frames_dropped_ += dropped;
      }
      continue;
    }
    const Error& error = frame.error();
    if (error.code == ErrorCode::kOutOfRange) {
      SetState(SourceState::kFinished, error.message);
      return;
    }
    if (error.code == ErrorCode::kUnavailable && source_->live()) {
      SetState(SourceState::kReconnecting, error.message + "; reconnecting");
      source_->Close();
      if (!SleepFor(std::chrono::duration<double>(config_.reconnect_initial_backoff_s))) return;
      if (!OpenWithBackoff()) return;
      {
        std::lock_guard<std::mutex> lock(mu_);
        ++reconnects_;
      }
      SetState(SourceState::kRunning, "");
      continue;
    }
    // One unreadable frame of a recording: count it and go on, unless nothing works.
    {
      std::lock_guard<std::mutex> lock(mu_);
      ++frames_failed_;
    }
    const Clock::time_point now = Clock::now();
    if (last_bad_log == Clock::time_point{} || now - last_bad_log >= std::chrono::seconds(1)) {
      spdlog::warn(
          "source {}: skipping an unreadable frame: {}{}", source_->description(), error.message,
          bad_unlogged > 0
              ? " (and " + std::to_string(bad_unlogged) + " more since the last such message)"
              : "");
      last_bad_log = now;
      bad_unlogged = 0;
    } else {
      ++bad_unlogged;
    }
    if (++consecutive_bad >= kMaxConsecutiveBadFrames || error.code == ErrorCode::kUnavailable) {
      SetState(SourceState::kFailed, error.message);
      return;
    }
  }
}

bool PosePipeline::WaitForWarmUp() {
  std::unique_lock<std::mutex> lock(mu_);
  const bool waits = warm_ups_pending_ > 0 || other_warm_up_.valid();
  if (waits) reason_ = "estimators warming up, then the source opens";
  stop_cv_.wait(lock, [this] { return stopping_.load() || warm_ups_pending_ == 0; });
  lock.unlock();
  if (other_warm_up_.valid()) {
    while (other_warm_up_.wait_for(std::chrono::milliseconds(50)) != std::future_status::ready) {
      if (stopping_.load()) return false;
    }
  }
  lock.lock();
  if (waits && state_ == SourceState::kStarting) reason_ = "opening the source";
  return !stopping_.load();
}

void PosePipeline::WarmUp(Estimator* estimator) {
  const Clock::time_point start = Clock::now();
  // Rendered here (by the process's first caller), not in Start(): the daemon serves meanwhile.
  const std::shared_ptr<const SimulatedFrame> frame = WarmUpFrame();
  if (frame) {
    // The estimator keeps nothing of a frame but its buffers' capacity, and no tracker sees
    // this one: the stream's estimates are those it would give without the warm-up.
    const Result<Estimate> result = estimator->EstimateDepth(frame->depth, WarmUpIntrinsics());
    if (!result.ok()) spdlog::debug("warm-up estimate: {}", result.error().ToString());
  }
  const double ms = Seconds(Clock::now() - start) * 1e3;
  std::lock_guard<std::mutex> lock(mu_);
  warm_up_ms_ = std::max(warm_up_ms_, ms);
  if (--warm_ups_pending_ > 0) return;
  if (frame) {
    warmed_up_ = true;
    spdlog::info("estimators warmed up on a synthetic frame in {:.0f} ms", warm_up_ms_);
  }
  stop_cv_.notify_all();
}

void PosePipeline::EstimateLoop(Estimator* estimator) {
  if (config_.warm_up) WarmUp(estimator);
  // One tracker per estimation thread: with several threads each follows every n-th frame.
  PoseTracker tracker(estimator);
  if (config_.has_initial_pose) tracker.SetInitialPose(config_.initial_pose);
  std::uint64_t tracked_epoch = 0;
  while (!stopping_.load()) {
    std::optional<Frame> frame;
    std::uint64_t ticket = 0;
    {
      std::lock_guard<std::mutex> take(take_mu_);
      // Read before popping: when the capture had already ended, an empty queue stays empty.
      const bool capture_done = capture_done_.load();
      frame = queue_.Pop(std::chrono::milliseconds(100));
      if (!frame) {
        if (capture_done) break;
        continue;
      }
      std::lock_guard<std::mutex> lock(mu_);
      ticket = publish_order_.NextTicket();
    }
    const Clock::time_point start = Clock::now();
    if (frame->epoch != tracked_epoch) {  // the source (re)started: nothing to follow yet.
      tracker.Reset();
      tracked_epoch = frame->epoch;
    }
    Result<Estimate> result =
        config_.tracking
            ? (frame->is_cloud ? tracker.EstimateCloud(frame->cloud)
                               : tracker.EstimateDepth(frame->depth, frame->intrinsics))
            : (frame->is_cloud ? estimator->EstimateCloud(frame->cloud)
                               : estimator->EstimateDepth(frame->depth, frame->intrinsics));
    auto published = std::make_shared<PublishedEstimate>();
    published->sequence = frame->sequence;
    published->source_time_s = frame->source_time_s;
    published->received = frame->received;
    published->origin = frame->origin;
    published->ok = result.ok();
    if (result.ok()) {
      published->estimate = std::move(*result);
    } else {
      published->error = result.error();
    }
    published->source_epoch = frame->epoch;
    published->queue_s = Seconds(start - frame->received_steady);
    published->received_steady = frame->received_steady;
    if (observer_) published->frame = std::make_shared<const Frame>(std::move(*frame));
    Publish(ticket, std::move(published));
  }
  // The last estimation thread out, when the source ended rather than the pipeline stopping,
  // marks the pipeline ended (every ticket was handed in, so everything is published).
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (--estimators_running_ > 0 || stopping_.load()) return;
    ended_ = true;
  }
  published_cv_.notify_all();
  if (signal_ != nullptr) signal_->Notify();
}

void PosePipeline::Publish(std::uint64_t ticket, std::shared_ptr<PublishedEstimate> result) {
  std::vector<std::shared_ptr<PublishedEstimate>> ready;
  {
    std::lock_guard<std::mutex> lock(mu_);
    frames_dropped_ += publish_order_.Done(ticket, std::move(result), &ready);
    for (std::shared_ptr<PublishedEstimate>& published : ready) {
      published->published = Clock::now();
      published->published_wall = std::chrono::system_clock::now();
      published->latency_s = Seconds(published->published - published->received_steady);
      published->publish_id = next_publish_id_++;
      if (published->ok) {
        ++frames_estimated_;
        has_floor_ = true;
        last_floor_ = published->estimate.floor;
      } else {
        ++frames_failed_;
      }
      stats_.RecordPublish(published->published, published->latency_s);
      latest_ = published;
    }
  }
  if (ready.empty()) return;
  if (observer_) {
    for (const std::shared_ptr<PublishedEstimate>& published : ready) {
      if (published->frame != nullptr) observer_(*published, *published->frame);
    }
  }
  published_cv_.notify_all();
  if (signal_ != nullptr) signal_->Notify();
}

std::shared_ptr<const PublishedEstimate> PosePipeline::Latest() const {
  std::lock_guard<std::mutex> lock(mu_);
  return latest_;
}

std::shared_ptr<const PublishedEstimate> PosePipeline::WaitNewer(
    std::uint64_t after, std::chrono::steady_clock::time_point deadline) const {
  std::unique_lock<std::mutex> lock(mu_);
  published_cv_.wait_until(lock, deadline, [&] {
    return stopping_.load() || ended_ || (latest_ && latest_->publish_id > after);
  });
  return latest_;
}

bool PosePipeline::Ended() const {
  std::lock_guard<std::mutex> lock(mu_);
  return ended_;
}

bool PosePipeline::IsStale(const PublishedEstimate& e, std::string* reason) const {
  std::lock_guard<std::mutex> lock(mu_);
  return DescribeStaleness(state_, reason_, Seconds(Clock::now() - e.published),
                           config_.stale_after_s, "source", "estimate", reason);
}

void SetRatesAndLatency(const StatsSnapshot& stats, PipelineStatus* s) {
  s->input_rate_hz = stats.input_rate_hz;
  s->estimate_rate_hz = stats.estimate_rate_hz;
  s->latency_samples = stats.latency_samples;
  s->latency_median_s = stats.latency_median_s;
  s->latency_p99_s = stats.latency_p99_s;
  s->latency_last_s = stats.latency_last_s;
}

PipelineStatus PosePipeline::Status() const {
  std::lock_guard<std::mutex> lock(mu_);
  PipelineStatus s;
  s.state = state_;
  s.reason = reason_;
  if (source_) {
    s.kind = source_->kind();
    s.description = source_->description();
  }
  s.frames_in = frames_in_;
  s.frames_dropped = frames_dropped_;
  s.frames_estimated = frames_estimated_;
  s.frames_failed = frames_failed_;
  s.reconnects = reconnects_;
  s.has_camera = has_camera_;
  s.camera = camera_;
  s.point_clouds = point_clouds_;
  SetRatesAndLatency(stats_.Snapshot(Clock::now()), &s);
  s.has_floor = has_floor_;
  s.last_floor = last_floor_;
  s.warmed_up = warmed_up_;
  s.warm_up_ms = warm_up_ms_;
  return s;
}

}  // namespace hpose::server
