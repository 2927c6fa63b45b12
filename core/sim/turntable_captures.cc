#include "core/sim/turntable_captures.h"

#include <algorithm>
#include <cmath>

#include "core/sim/depth_renderer.h"
#include "core/sim/kinect_noise_model.h"
#include "core/sim/scene.h"

namespace hpose {

Pose2D TurntableRobotPose(const TurntableSpec& spec, double table_angle_rad) {
  const double c = std::cos(table_angle_rad), s = std::sin(table_angle_rad);
  const Pose2D& r = spec.robot_on_table;
  return Pose2D{spec.axis_ground.x() + c * r.x - s * r.y, spec.axis_ground.y() + s * r.x + c * r.y,
                NormalizeAngle(table_angle_rad + r.theta)};
}

Result<TurntableCaptures> SimulateTurntableCaptures(const TurntableSpec& spec) {
  if (spec.views < 1 || spec.views > 360) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "turntable views must be in [1, 360], got " + std::to_string(spec.views));
  }
  if (!spec.angle_errors_rad.empty() &&
      static_cast<int>(spec.angle_errors_rad.size()) != spec.views) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "turntable: " + std::to_string(spec.angle_errors_rad.size()) +
                         " angle errors for " + std::to_string(spec.views) + " views");
  }
  if (!(spec.table_height_m >= 0.0 && spec.table_height_m <= 1.0) ||
      !(spec.table_radius_m >= 0.0 && spec.table_radius_m <= 2.0)) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "turntable height must be in [0, 1] m and radius in [0, 2] m");
  }
  if (!spec.axis_ground.allFinite() || !std::isfinite(spec.step_rad) ||
      !std::isfinite(spec.start_angle_rad)) {
    return MakeError(ErrorCode::kInvalidArgument, "turntable axis and angles must be finite");
  }
  const double robot_offset = std::hypot(spec.robot_on_table.x, spec.robot_on_table.y);
  if (spec.table_height_m > 0.0 && robot_offset >= spec.table_radius_m) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "the robot (" + std::to_string(robot_offset) +
                         " m from the axis) does not stand on the turntable disc of radius " +
                         std::to_string(spec.table_radius_m) + " m");
  }
  Result<HumanoidJoints> joints = HumanoidJoints::Preset(spec.preset);
  if (!joints.ok()) return joints.error();
  Result<HumanoidModel> model = HumanoidModel::Create(spec.dimensions, *joints);
  if (!model.ok()) return model.error();

  TurntableCaptures out;
  out.humanoid_height_m = model->Height();
  for (int i = 0; i < spec.views; ++i) {
    const double error = spec.angle_errors_rad.empty() ? 0.0 : spec.angle_errors_rad[i];
    const double angle = NormalizeAngle(spec.start_angle_rad + i * spec.step_rad + error);
    out.table_angles_rad.push_back(angle);
    out.robot_poses.push_back(TurntableRobotPose(spec, angle));
    out.noise_seeds.push_back(spec.seed * 1000003ULL + static_cast<std::uint64_t>(i));
  }

  // Still clutter, laid out clear of the robot in every view and of the disc.
  std::vector<Primitive> clutter;
  if (spec.clutter > 0) {
    Scene layout;
    for (const Pose2D& p : out.robot_poses) layout.AddHumanoid(*model, p);
    layout.AddHumanoid(*model, Pose2D{spec.axis_ground.x(), spec.axis_ground.y(), 0.0});
    ClutterOptions options;
    options.clearance_m = std::max(options.clearance_m, spec.table_radius_m);
    if (Status s = layout.AddRandomClutter(spec.clutter, spec.seed, options); !s.ok()) {
      return s.error();
    }
    clutter = layout.clutter();
  }

  out.sensor_mount = FloorEstimate::FromHeightPitchRoll(spec.sensor_height_m, spec.sensor_pitch_rad,
                                                        spec.sensor_roll_rad);
  Result<DepthRenderer> renderer = DepthRenderer::Create(spec.intrinsics, out.sensor_mount);
  if (!renderer.ok()) return renderer.error();
  KinectNoiseOptions noise_options;
  noise_options.noise_enabled = spec.noise;
  Result<KinectNoiseModel> noise = KinectNoiseModel::Create(noise_options);
  if (!noise.ok()) return noise.error();

  for (int i = 0; i < spec.views; ++i) {
    Scene scene;
    for (const Primitive& c : clutter) scene.AddClutter(c);
    if (spec.table_height_m > 0.0 && spec.table_radius_m > 0.0) {
      Eigen::Isometry3d disc = Eigen::Isometry3d::Identity();
      disc.translation() << spec.axis_ground, 0.5 * spec.table_height_m;
      scene.AddClutter(
          Primitive::Cylinder("turntable", spec.table_radius_m, spec.table_height_m, disc));
    }
    // The robot stands on the table top: its primitives are placed as still objects lifted by
    // the table height (Scene humanoids stand on the floor).
    Eigen::Isometry3d ground_from_robot = out.robot_poses[i].ToIsometry();
    ground_from_robot.translation().z() = spec.table_height_m;
    for (const Primitive& part : model->primitives()) {
      if (Status s = scene.AddClutter(part.Transformed(ground_from_robot)); !s.ok()) {
        return s.error();
      }
    }
    out.depth.push_back(renderer->Render(scene, &*noise, out.noise_seeds[i]));
  }
  return out;
}

}  // namespace hpose
