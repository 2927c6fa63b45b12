#include "core/stereo/object_motion_detector.h"

namespace hpose {

ObjectMotionDetector::ObjectMotionDetector(const ObjectMotionDetectorOptions& options)
    : options_(options) {}

void ObjectMotionDetector::Reset() {
  history_.clear();
  has_reference_ = false;
  last_distance_m_ = 0.0;
}

bool ObjectMotionDetector::Update(double t_s, const Eigen::Vector2d& position_m) {
  if (!history_.empty() && t_s < history_.back().t_s) Reset();
  // Keep just what the reference window can still use.
  while (!history_.empty() && history_.front().t_s < t_s - options_.reference_oldest_s - 1e-9) {
    history_.pop_front();
  }
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  int count = 0;
  for (const Sample& s : history_) {
    const double age = t_s - s.t_s;
    if (age >= options_.reference_newest_s - 1e-9 && age <= options_.reference_oldest_s + 1e-9) {
      sum += s.position_m;
      ++count;
    }
  }
  history_.push_back({t_s, position_m});
  has_reference_ = count >= options_.min_reference_frames;
  if (!has_reference_) {
    last_distance_m_ = 0.0;
    return false;
  }
  reference_mean_ = sum / count;
  last_distance_m_ = (position_m - reference_mean_).norm();
  return last_distance_m_ >= options_.threshold_m;
}

}  // namespace hpose
