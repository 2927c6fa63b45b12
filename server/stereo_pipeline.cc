#include "server/stereo_pipeline.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <utility>
#include <vector>

#include "server/pipeline_stats.h"

namespace hpose::server {

namespace {

using Clock = std::chrono::steady_clock;

constexpr int kMaxConsecutiveBadPairs = 100;

}  // namespace

StereoPipeline::StereoPipeline(StereoSequence sequence, const StereoEstimator* estimator,
                               StereoConfig config, PublishSignal* signal)
    : sequence_(std::move(sequence)),
      estimator_(estimator),
      config_(std::move(config)),
      signal_(signal) {}

StereoPipeline::~StereoPipeline() { Stop(); }

void StereoPipeline::Start() {
  if (started_) return;
  started_ = true;
  thread_ = std::thread([this] { Run(); });
}

void StereoPipeline::Stop() {
  if (stopping_.exchange(true)) return;
  {
    std::lock_guard<std::mutex> lock(mu_);
    stop_cv_.notify_all();
    published_cv_.notify_all();
  }
  if (signal_ != nullptr) signal_->Notify();
  if (thread_.joinable()) thread_.join();
}

void StereoPipeline::SetState(SourceState state, std::string reason) {
  {
    std::lock_guard<std::mutex> lock(mu_);
    LogSourceStateChange("stereo source " + sequence_.dir(), state_, state, reason);
    state_ = state;
    reason_ = std::move(reason);
  }
  if (Ended()) {  // wake the waiters: nothing will follow.
    published_cv_.notify_all();
    if (signal_ != nullptr) signal_->Notify();
  }
}

bool StereoPipeline::SleepUntil(Clock::time_point t) {
  std::unique_lock<std::mutex> lock(mu_);
  stop_cv_.wait_until(lock, t, [this] { return stopping_.load(); });
  return !stopping_.load();
}

void StereoPipeline::Publish(std::shared_ptr<PublishedStereoEstimate> e, bool robot_found) {
  {
    std::lock_guard<std::mutex> lock(mu_);
    e->publish_id = next_publish_id_++;
    if (robot_found) {
      ++frames_estimated_;
    } else {
      ++frames_failed_;
    }
    stats_.RecordPublish(e->published, e->latency_s);
    latest_ = std::move(e);
  }
  published_cv_.notify_all();
  if (signal_ != nullptr) signal_->Notify();
}

void StereoPipeline::Run() {
  const size_t n = sequence_.size();
  if (n == 0) {
    SetState(SourceState::kFailed, sequence_.dir() + ": no stereo frame pairs");
    return;
  }
  SetState(SourceState::kRunning, "");
  const double t_first = sequence_.frame(0).timestamp_s;
  std::uint64_t sequence_number = 0;
  std::uint64_t epoch = 0;
  int consecutive_bad = 0;
  for (; !stopping_.load(); ++epoch) {
    tracker_.Reset();
    const Clock::time_point loop_start = Clock::now();
    auto due = [&](size_t i) {
      return loop_start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
                              sequence_.frame(i).timestamp_s - t_first));
    };
    for (size_t i = 0; i < n && !stopping_.load(); ++i) {
      ++sequence_number;
      if (config_.realtime) {
        if (i + 1 < n && Clock::now() >= due(i + 1)) {  // behind: the next pair is due already.
          std::lock_guard<std::mutex> lock(mu_);
          ++frames_dropped_;
          continue;
        }
        if (!SleepUntil(due(i))) return;
      }
      const StereoFrameEntry& entry = sequence_.frame(i);
      auto e = std::make_shared<PublishedStereoEstimate>();
      e->sequence = sequence_number;
      e->source_epoch = epoch;
      e->source_time_s = entry.timestamp_s;
      e->received = std::chrono::system_clock::now();
      e->origin = std::filesystem::path(entry.left_path).filename().string();
      const Clock::time_point read_start = Clock::now();
      {
        std::lock_guard<std::mutex> lock(mu_);
        ++frames_in_;
        stats_.RecordInput(read_start);
      }
      bool robot_found = false;
      Result<std::pair<RgbImage, RgbImage>> pair = sequence_.Load(i);
      if (!pair.ok()) {
        e->error = pair.error();
      } else {
        NoteCamera(pair->first.width, pair->first.height);
        const Clock::time_point process_start = Clock::now();
        StereoObjectPrior prior;
        Result<StereoFrameResult> result =
            estimator_->Process(pair->first, pair->second, entry.timestamp_s,
                                tracker_.ObjectPrior(&prior) ? &prior : nullptr);
        e->process_s = Seconds(Clock::now() - process_start);
        if (!result.ok()) {
          e->error = result.error();
          e->error.message = entry.left_path + ": " + e->error.message;
        } else {
          e->ok = true;
          e->frame = std::move(*result);
          e->track = tracker_.Update(e->frame);
          robot_found = e->frame.ok();
        }
      }
      consecutive_bad = e->ok ? 0 : consecutive_bad + 1;
      e->published = Clock::now();
      e->published_wall = std::chrono::system_clock::now();
      e->latency_s = Seconds(e->published - read_start);
      const std::string last_error = e->ok ? "" : e->error.message;
      Publish(std::move(e), robot_found);
      if (consecutive_bad >= kMaxConsecutiveBadPairs) {
        SetState(SourceState::kFailed, "no readable pair in the last " +
                                           std::to_string(kMaxConsecutiveBadPairs) +
                                           " (last: " + last_error + ")");
        return;
      }
    }
    if (!config_.loop) break;
  }
  if (!stopping_.load()) {
    SetState(SourceState::kFinished,
             "end of " + sequence_.dir() + " (" + std::to_string(n) + " pairs)");
  }
}

std::shared_ptr<const PublishedStereoEstimate> StereoPipeline::Latest() const {
  std::lock_guard<std::mutex> lock(mu_);
  return latest_;
}

std::shared_ptr<const PublishedStereoEstimate> StereoPipeline::WaitNewer(
    std::uint64_t after, Clock::time_point deadline) const {
  std::unique_lock<std::mutex> lock(mu_);
  published_cv_.wait_until(lock, deadline, [&] {
    return stopping_.load() || EndedLocked() || (latest_ && latest_->publish_id > after);
  });
  return latest_;
}

bool StereoPipeline::EndedLocked() const {
  return state_ == SourceState::kFinished || state_ == SourceState::kFailed;
}

bool StereoPipeline::Ended() const {
  std::lock_guard<std::mutex> lock(mu_);
  return EndedLocked();
}

bool StereoPipeline::IsStale(const PublishedStereoEstimate& e, std::string* reason) const {
  std::lock_guard<std::mutex> lock(mu_);
  return DescribeStaleness(state_, reason_, Seconds(Clock::now() - e.published),
                           config_.stale_after_s, "stereo source", "stereo estimate", reason);
}

void StereoPipeline::NoteCamera(int width, int height) {
  const Eigen::Matrix3d& k = estimator_->rig().calibration().left.camera_matrix;
  std::lock_guard<std::mutex> lock(mu_);
  has_camera_ = true;
  camera_.width = width;
  camera_.height = height;
  camera_.fx = k(0, 0);
  camera_.fy = k(1, 1);
  camera_.cx = k(0, 2);
  camera_.cy = k(1, 2);
}

PipelineStatus StereoPipeline::Status() const {
  std::lock_guard<std::mutex> lock(mu_);
  PipelineStatus s;
  s.state = state_;
  s.reason = reason_;
  s.kind = "stereo-dir";
  s.description = sequence_.dir();
  s.frames_in = frames_in_;
  s.frames_dropped = frames_dropped_;
  s.frames_estimated = frames_estimated_;
  s.frames_failed = frames_failed_;
  s.has_camera = has_camera_;
  s.camera = camera_;
  SetRatesAndLatency(stats_.Snapshot(Clock::now()), &s);
  return s;
}

}  // namespace hpose::server
