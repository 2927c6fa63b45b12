#ifndef HPOSE_CORE_STEREO_OBJECT_MOTION_DETECTOR_H_
#define HPOSE_CORE_STEREO_OBJECT_MOTION_DETECTOR_H_

#include <deque>

#include <Eigen/Core>

namespace hpose {

struct ObjectMotionDetectorOptions {
  // The object is moving when it is at least this far from the reference mean, metres.
  double threshold_m = 0.10;
  // The reference mean is over the positions observed between these ages, seconds
  // (the paper: the 8 frames from about 1.0 s to 0.5 s ago).
  double reference_oldest_s = 1.0;
  double reference_newest_s = 0.5;
  // With fewer reference positions than this the state is unknown (reported as not moving).
  int min_reference_frames = 3;
};

// Stop/move detection of the object on the floor: compares the current position with the mean
// of the positions observed between reference_oldest_s and reference_newest_s ago.
class ObjectMotionDetector final {
 public:
  explicit ObjectMotionDetector(const ObjectMotionDetectorOptions& options = {});

  // Adds an observation (world frame, metres; seconds, increasing) and returns whether the
  // object is moving now. An observation older than the previous one clears the history first.
  bool Update(double t_s, const Eigen::Vector2d& position_m);

  // The reference mean used by the last Update (valid when has_reference()).
  const Eigen::Vector2d& reference_mean() const { return reference_mean_; }
  bool has_reference() const { return has_reference_; }
  double last_distance_m() const { return last_distance_m_; }
  void Reset();

 private:
  struct Sample {
    double t_s;
    Eigen::Vector2d position_m;
  };
  ObjectMotionDetectorOptions options_;
  std::deque<Sample> history_;
  Eigen::Vector2d reference_mean_ = Eigen::Vector2d::Zero();
  bool has_reference_ = false;
  double last_distance_m_ = 0.0;
};

}  // namespace hpose

#endif  // HPOSE_CORE_STEREO_OBJECT_MOTION_DETECTOR_H_
