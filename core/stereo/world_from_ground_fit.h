#ifndef HPOSE_CORE_STEREO_WORLD_FROM_GROUND_FIT_H_
#define HPOSE_CORE_STEREO_WORLD_FROM_GROUND_FIT_H_

#include <string>
#include <vector>

#include "core/common/pose2d.h"
#include "core/common/status.h"

namespace hpose {

// The same point of the robot at one instant, as the depth estimator reports it (ground frame
// of the depth sensor) and as the stereo-marker estimator reports it (world frame of the
// landmarks). Metres, radians.
struct GroundWorldPair {
  double timestamp_s = 0.0;
  Pose2D ground;
  Pose2D world;
};

struct WorldFromGroundOptions {
  // A pair whose position residual exceeds max(this, 3 robust sigmas) is an outlier, metres.
  double outlier_threshold_m = 0.06;
  // ...or whose heading residual exceeds this, radians.
  double outlier_heading_rad = 0.35;
  // Below this spread of the robot's positions (the smaller axis of their scatter ellipse is
  // not used: a straight walk fixes the rotation), the rotation comes from the headings alone.
  double min_position_spread_m = 0.15;
  int max_iterations = 10;
};

// world_from_ground as a 2D rigid transform (x, y, yaw), with what supports it.
struct WorldFromGroundFit {
  Pose2D world_from_ground;  // the ground frame's origin and x axis in the world frame.
  int pairs = 0;
  int inliers = 0;
  double rms_m = 0.0;  // position residual of the inliers.
  double max_m = 0.0;
  double heading_rms_rad = 0.0;
  // Standard deviations of the inlier positions along the major and minor axes, metres.
  double spread_major_m = 0.0;
  double spread_minor_m = 0.0;
  bool rotation_from_positions = true;  // false: from the headings (the robot hardly moved).
  std::string observability;            // a sentence on what the motion made observable.
  std::vector<double> residuals_m;      // per pair, in input order.
  std::vector<bool> inlier;             // per pair.
};

// Least-squares 2D rigid fit world = R(yaw) ground + t over the pairs, with iterative outlier
// rejection. As in SPEC §3, what can be identified depends on the motion: positions spread
// along a line or an area fix the yaw and the translation; a robot that stood still fixes the
// translation only through the yaw taken from its headings. Fails with kInvalidArgument for
// fewer than 3 pairs or non-finite values, and kFailedPrecondition when fewer than 3 pairs
// survive the outlier rejection.
Result<WorldFromGroundFit> FitWorldFromGround(const std::vector<GroundWorldPair>& pairs,
                                              const WorldFromGroundOptions& options = {});

// A pose one estimator reported at one instant (seconds, the recording's clock).
struct TimedPose {
  double timestamp_s = 0.0;
  Pose2D pose;
};

// Pairs every ground pose (depth estimator) with the world pose (stereo estimator) nearest to
// it in time, when they are at most `max_dt_s` apart; a world pose may serve several ground
// poses. The pair's timestamp is the ground pose's. Neither list needs to be sorted; the
// result follows the order of `ground`.
std::vector<GroundWorldPair> PairPosesByTime(const std::vector<TimedPose>& ground,
                                             const std::vector<TimedPose>& world, double max_dt_s);

}  // namespace hpose

#endif  // HPOSE_CORE_STEREO_WORLD_FROM_GROUND_FIT_H_
