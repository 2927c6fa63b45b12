#ifndef HPOSE_CORE_STEREO_PATH_LINE_FIT_H_
#define HPOSE_CORE_STEREO_PATH_LINE_FIT_H_

#include <vector>

#include <Eigen/Core>

#include "core/common/status.h"

namespace hpose {

// A timed position on the floor (world frame, metres; seconds).
struct TimedPosition {
  double t_s = 0.0;
  Eigen::Vector2d position_m = Eigen::Vector2d::Zero();
};

// A straight path at constant velocity, p(t) = origin + velocity * (t - t0).
struct PathPrediction {
  double t0_s = 0.0;                                   // reference time.
  Eigen::Vector2d origin_m = Eigen::Vector2d::Zero();  // position at t0.
  Eigen::Vector2d velocity_mps = Eigen::Vector2d::Zero();
  double rms_residual_m = 0.0;  // of the fitted frames.
  int frames = 0;

  Eigen::Vector2d PositionAt(double t_s) const { return origin_m + velocity_mps * (t_s - t0_s); }
  double Speed() const { return velocity_mps.norm(); }

  // When the path passes closest to `point` and how close. For a (nearly) stationary path the
  // time is t0 and the distance that of origin. The time may lie in the past.
  struct Approach {
    double t_s = 0.0;
    double distance_m = 0.0;
  };
  Approach ClosestApproach(const Eigen::Vector2d& point) const;
};

// Least-squares straight-line fit of position against time (x(t) and y(t) each a line), i.e.
// the path's direction and speed, with t0 = `t0_s`. Fails with kInvalidArgument for fewer than
// two samples, non-finite values, or when all samples share one time.
Result<PathPrediction> FitPathLine(const std::vector<TimedPosition>& samples, double t0_s);

}  // namespace hpose

#endif  // HPOSE_CORE_STEREO_PATH_LINE_FIT_H_
