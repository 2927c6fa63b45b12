#ifndef HPOSE_CORE_SIM_TURNTABLE_CAPTURES_H_
#define HPOSE_CORE_SIM_TURNTABLE_CAPTURES_H_

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/common/pose2d.h"
#include "core/common/status.h"
#include "core/depth/depth_image.h"
#include "core/depth/floor_estimate.h"
#include "core/depth/intrinsics.h"
#include "core/sim/humanoid_model.h"

namespace hpose {

// A humanoid standing on a turntable in front of a fixed depth sensor, turned between views: the
// captures `hpose template from-captures` makes a 360 degree template from. Ground frame as
// everywhere (origin on the floor below the sensor, x along the optical axis, z up); metres,
// radians.
struct TurntableSpec {
  std::string preset = "standing";  // humanoid joint preset (HumanoidJoints::Preset).
  HumanoidDimensions dimensions;
  // Where the turntable's vertical axis meets the floor, ground frame. The estimator does not
  // know it.
  Eigen::Vector2d axis_ground = Eigen::Vector2d(1.2, 0.04);
  // The robot frame in the table frame (table frame: origin on the axis at the table top,
  // z up, x = the ground x axis when the table angle is 0). Off-centre on purpose.
  Pose2D robot_on_table{0.035, -0.025, 0.0};
  // The disc: radius and height of its top above the floor. Height 0: no disc, the robot stands
  // on the floor and turns about the axis (e.g. a flat plate flush with the floor).
  double table_radius_m = 0.22;
  double table_height_m = 0.02;
  // Table angle of view i (counter-clockwise seen from above): start + i * step + error_i, with
  // error_i from `angle_errors_rad` when given (hand-turned views), else 0.
  int views = 12;
  double start_angle_rad = 0.0;
  double step_rad = kPi / 6.0;
  std::vector<double> angle_errors_rad;
  // Sensor mount (FloorEstimate conventions) and image.
  double sensor_height_m = 0.34;
  double sensor_pitch_rad = 0.0;
  double sensor_roll_rad = 0.0;
  Intrinsics intrinsics = Intrinsics::KinectV1(640, 480);
  bool noise = true;       // Kinect v1 noise model (SPEC 5).
  std::uint64_t seed = 1;  // noise of view i is drawn from seed * 1000003 + i; clutter from seed.
  int clutter = 0;         // random objects standing on the floor, away from the table (still).
};

struct TurntableCaptures {
  std::vector<DepthImage> depth;           // one per view.
  std::vector<double> table_angles_rad;    // the true table angle of each view.
  std::vector<Pose2D> robot_poses;         // the robot frame in the ground frame, per view.
  FloorEstimate sensor_mount;              // the true floor (ground_from_sensor).
  double humanoid_height_m = 0.0;          // above its soles (the table top).
  std::vector<std::uint64_t> noise_seeds;  // per view.
};

// The robot frame in the ground frame for a table angle: ground_from_table * table_from_robot.
Pose2D TurntableRobotPose(const TurntableSpec& spec, double table_angle_rad);

// Renders every view. Fails (kInvalidArgument) on an unknown preset, bad intrinsics, a sensor
// below the floor, fewer than 1 or more than 360 views, angle errors whose count differs from
// the views, a negative table size or a robot that does not stand on the disc (its origin off
// the disc); kFailedPrecondition when the clutter does not fit.
Result<TurntableCaptures> SimulateTurntableCaptures(const TurntableSpec& spec);

}  // namespace hpose

#endif  // HPOSE_CORE_SIM_TURNTABLE_CAPTURES_H_
