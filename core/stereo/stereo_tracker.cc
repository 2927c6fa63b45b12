#include "core/stereo/stereo_tracker.h"

#include <cmath>

namespace hpose {

StereoTracker::StereoTracker(const StereoTrackerOptions& options)
    : options_(options), detector_(options.motion) {}

void StereoTracker::Reset() {
  robot_history_.clear();
  detector_.Reset();
  last_time_s_ = -1e300;
  have_object_before_ = false;
  moving_ = false;
  not_moving_count_ = 0;
  path_samples_.clear();
  path_valid_ = false;
}

StereoTrackState StereoTracker::Update(const StereoFrameResult& frame) {
  if (frame.timestamp_s < last_time_s_) Reset();
  last_time_s_ = frame.timestamp_s;
  StereoTrackState state;
  state.timestamp_s = frame.timestamp_s;

  if (frame.ok()) {
    robot_history_.push_back(frame.robot);
    while (static_cast<int>(robot_history_.size()) > options_.robot_average_frames) {
      robot_history_.pop_front();
    }
  }
  if (!robot_history_.empty()) {
    double sx = 0, sy = 0, ss = 0, sc = 0;
    for (const Pose2D& p : robot_history_) {
      sx += p.x;
      sy += p.y;
      ss += std::sin(p.theta);
      sc += std::cos(p.theta);
    }
    const double n = static_cast<double>(robot_history_.size());
    state.robot_valid = true;
    state.robot_mean.x = sx / n;
    state.robot_mean.y = sy / n;
    state.robot_mean.theta = NormalizeAngle(std::atan2(ss, sc));
    state.robot_frames = static_cast<int>(robot_history_.size());
  }

  if (frame.object_in_world) {
    const Eigen::Vector2d xy = frame.object_world_m.head<2>();
    const bool moving_now = detector_.Update(frame.timestamp_s, xy);
    if (!moving_ && moving_now) {
      moving_ = true;
      not_moving_count_ = 0;
      motion_start_s_ = frame.timestamp_s;
      motion_t0_s_ = have_object_before_ ? last_object_time_s_ : frame.timestamp_s;
      path_samples_.clear();
      path_valid_ = false;
    } else if (moving_) {
      not_moving_count_ = moving_now ? 0 : not_moving_count_ + 1;
      if (not_moving_count_ >= options_.stop_frames) {
        moving_ = false;
        path_samples_.clear();
        path_valid_ = false;
      }
    }
    if (moving_ && static_cast<int>(path_samples_.size()) < options_.path_fit_frames) {
      path_samples_.push_back({frame.timestamp_s, xy});
      if (static_cast<int>(path_samples_.size()) == options_.path_fit_frames) {
        Result<PathPrediction> fit = FitPathLine(path_samples_, motion_t0_s_);
        path_valid_ = fit.ok();
        if (fit.ok()) path_ = *fit;
      }
    }
    last_object_time_s_ = frame.timestamp_s;
    last_object_world_m_ = frame.object_world_m;
    have_object_before_ = true;
    state.object_valid = true;
    state.object_world_m = frame.object_world_m;
  }
  state.object_moving = moving_;
  state.motion_start_s = moving_ ? motion_start_s_ : 0.0;
  state.path_valid = moving_ && path_valid_;
  if (state.path_valid) state.path = path_;
  return state;
}

bool StereoTracker::ObjectPrior(StereoObjectPrior* prior) const {
  if (!have_object_before_) return false;
  prior->world_m = last_object_world_m_;
  prior->timestamp_s = last_object_time_s_;
  return true;
}

}  // namespace hpose
