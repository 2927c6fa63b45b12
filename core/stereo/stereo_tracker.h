#ifndef HPOSE_CORE_STEREO_STEREO_TRACKER_H_
#define HPOSE_CORE_STEREO_STEREO_TRACKER_H_

#include <deque>
#include <vector>

#include <Eigen/Core>

#include "core/common/pose2d.h"
#include "core/stereo/object_motion_detector.h"
#include "core/stereo/path_line_fit.h"
#include "core/stereo/stereo_estimator.h"
#include "core/stereo/stereo_frame_result.h"

namespace hpose {

struct StereoTrackerOptions {
  int robot_average_frames = 8;  // the robot pose is the mean of the last N valid frames.
  ObjectMotionDetectorOptions motion;
  int path_fit_frames = 8;  // frames after motion starts used for the straight-line fit.
  // Motion ends after this many consecutive frames judged not moving.
  int stop_frames = 3;
};

// What the tracker knows after a frame. World frame, metres, seconds.
struct StereoTrackState {
  double timestamp_s = 0.0;
  bool robot_valid = false;
  Pose2D robot_mean;  // mean of the last robot_frames valid poses (circular mean of theta).
  int robot_frames = 0;
  bool object_valid = false;  // the object was located in the world in this frame.
  Eigen::Vector3d object_world_m = Eigen::Vector3d::Zero();
  bool object_moving = false;
  double motion_start_s = 0.0;  // time of the first frame judged moving (when object_moving).
  bool path_valid = false;      // a path has been fitted for the current motion.
  PathPrediction path;          // t0 = the last frame before motion was detected.
};

// The temporal part of the stereo-marker estimator: averaging of the robot pose, stop/move
// detection of the object and prediction of its path by a straight-line fit.
class StereoTracker final {
 public:
  explicit StereoTracker(const StereoTrackerOptions& options = {});

  // Feeds one frame result (in time order; a frame older than the last clears all history).
  StereoTrackState Update(const StereoFrameResult& frame);
  void Reset();

  // The object's last world position and its time, for StereoEstimator::Process to continue
  // the track; false before the object has been located.
  bool ObjectPrior(StereoObjectPrior* prior) const;

 private:
  StereoTrackerOptions options_;
  std::deque<Pose2D> robot_history_;
  ObjectMotionDetector detector_;
  double last_time_s_ = -1e300;
  double last_object_time_s_ = 0.0;
  bool have_object_before_ = false;
  Eigen::Vector3d last_object_world_m_ = Eigen::Vector3d::Zero();
  bool moving_ = false;
  int not_moving_count_ = 0;
  double motion_start_s_ = 0.0;
  double motion_t0_s_ = 0.0;
  std::vector<TimedPosition> path_samples_;
  bool path_valid_ = false;
  PathPrediction path_;
};

}  // namespace hpose

#endif  // HPOSE_CORE_STEREO_STEREO_TRACKER_H_
