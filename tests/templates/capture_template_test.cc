// A template made from simulated turntable captures, used by the Estimator on fresh frames of
// the same robot, gives the estimates the generated template (HumanoidModel::SampleSurface)
// gives. Both templates get their origin by the same rule (VoxelCentroidXY: below the centroid
// of the occupied voxels, geometry both have), and their x axis is the robot's forward
// direction: the generated one by construction, the captured one because the robot faced the
// sensor in capture 0 (--front-view 0).
#include "core/templates/capture_template.h"

#include <algorithm>
#include <cmath>
#include <iostream>

#include <gtest/gtest.h>

#include "tests/sanitizer_build.h"

#include "core/depth/depth_to_cloud.h"
#include "core/search/estimator.h"
#include "core/sim/frame_simulator.h"
#include "core/sim/turntable_captures.h"
#include "core/templates/capture_registration.h"
#include "core/templates/capture_views.h"

namespace hpose {
namespace {

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// The generated template of the same robot, origin below its voxel centroid. `centroid` gets
// where that origin is in the robot (torso) frame.
VoxelTemplate GeneratedTemplate(const std::string& preset, Eigen::Vector2d* centroid) {
  const HumanoidModel model = *HumanoidModel::FromPreset(preset);
  std::vector<Eigen::Vector3f> pts = *model.SampleSurface(0.004);
  *centroid = VoxelCentroidXY(pts, 0.016);
  for (Eigen::Vector3f& p : pts) p.head<2>() -= centroid->cast<float>();
  return *MakeTemplateFromPoints(pts, "generated", 0.016);
}

Result<CaptureTemplate> CapturedTemplate(const TurntableSpec& spec) {
  Result<TurntableCaptures> captures = SimulateTurntableCaptures(spec);
  if (!captures.ok()) return captures.error();
  std::vector<CaptureView> views;
  DepthToCloudOptions cloud_options;
  cloud_options.keep_organised = true;
  for (size_t i = 0; i < captures->depth.size(); ++i) {
    Result<PointCloud> cloud = DepthToCloud(captures->depth[i], spec.intrinsics, cloud_options);
    if (!cloud.ok()) return cloud.error();
    views.push_back({"capture_" + std::to_string(i), *cloud});
  }
  CaptureViewOptions view_options;
  view_options.table_height_m = spec.table_height_m;
  Result<CaptureViews> robot_views = ExtractRobotViews(views, view_options);
  if (!robot_views.ok()) return robot_views.error();
  CaptureRegistrationOptions reg_options;
  for (int i = 0; i < spec.views; ++i) reg_options.angles_rad.push_back(i * spec.step_rad);
  Result<CaptureRegistration> reg = RegisterCaptureViews(*robot_views, reg_options);
  if (!reg.ok()) return reg.error();
  CaptureTemplateOptions tpl_options;
  tpl_options.name = "captured";
  return MakeCaptureTemplate(*reg, tpl_options);
}

TEST(CaptureTemplateTest, EstimatesMatchTheGeneratedTemplatesOnFreshFrames) {
  HPOSE_SKIP_IF_SANITIZED();
  // Twelve noisy captures, robot off the axis, facing the sensor in capture 0, clutter around.
  TurntableSpec spec;
  spec.axis_ground = Eigen::Vector2d(1.25, 0.05);
  spec.robot_on_table = Pose2D{0.03, -0.04, 0.0};
  spec.clutter = 2;
  spec.seed = 11;
  const Pose2D at0 = TurntableRobotPose(spec, 0.0);
  spec.robot_on_table.theta = std::atan2(-at0.y, -at0.x);  // faces the sensor in capture 0.
  Result<CaptureTemplate> captured = CapturedTemplate(spec);
  ASSERT_TRUE(captured.ok()) << captured.error().ToString();
  Eigen::Vector2d centroid;
  const VoxelTemplate generated = GeneratedTemplate(spec.preset, &centroid);

  // The captured template's frame against the truth: its origin should be the generated one's
  // (the voxel centroid), its x axis the robot's forward direction.
  const Pose2D& r = spec.robot_on_table;
  const Eigen::Vector2d true_origin_table(
      r.x + std::cos(r.theta) * centroid.x() - std::sin(r.theta) * centroid.y(),
      r.y + std::sin(r.theta) * centroid.x() + std::cos(r.theta) * centroid.y());
  const Eigen::Vector2d origin_table(captured->table_from_template.x,
                                     captured->table_from_template.y);
  const double origin_error = (origin_table - true_origin_table).norm();
  const double yaw_error = std::abs(AngleDiff(captured->table_from_template.theta, r.theta));
  std::cout << "captured template: " << captured->tpl.voxels.size() << " voxels (generated "
            << generated.voxels.size() << "), origin " << origin_error * 1000.0 << " mm and x axis "
            << RadToDeg(yaw_error) << " deg from the true ones\n";
  EXPECT_LT(origin_error, 0.008);
  EXPECT_LT(yaw_error, DegToRad(1.5));

  auto with_captured =
      std::move(Estimator::Create(DefaultEstimatorOptions(), {captured->tpl}).value());
  auto with_generated =
      std::move(Estimator::Create(DefaultEstimatorOptions(), {generated}).value());
  std::vector<double> dtheta, dpos, theta_error_captured, theta_error_generated, pos_error_captured,
      pos_error_generated;
  int frames = 0;
  // 60 fresh frames: 1-3 m, every 30 degrees (shifted with the distance), clutter around.
  for (const double distance : {1.0, 1.5, 2.0, 2.5, 3.0}) {
    for (int k = 0; k < 12; ++k) {
      const double heading_deg = -165.0 + 30.0 * k + 7.0 * distance;
      FrameSpec frame_spec;
      frame_spec.humanoid_pose = Pose2D{distance, 0.1 - 0.05 * distance, DegToRad(heading_deg)};
      frame_spec.seed = 100 + frames++;
      frame_spec.clutter = 2;
      const SimulatedFrame frame = *SimulateFrame(frame_spec);
      Result<Estimate> a = with_captured->EstimateDepth(frame.depth, frame_spec.intrinsics);
      Result<Estimate> b = with_generated->EstimateDepth(frame.depth, frame_spec.intrinsics);
      ASSERT_TRUE(a.ok() && b.ok());
      ASSERT_FALSE(a->Humanoids().empty()) << distance << " m, " << heading_deg << " deg";
      ASSERT_FALSE(b->Humanoids().empty()) << distance << " m, " << heading_deg << " deg";
      const Pose2D pa = a->Humanoids().front().best.pose;
      const Pose2D pb = b->Humanoids().front().best.pose;
      dtheta.push_back(std::abs(AngleDiff(pa.theta, pb.theta)));
      dpos.push_back(std::hypot(pa.x - pb.x, pa.y - pb.y));
      // For information: both against the truth (the centroid origin of the posed robot).
      const Pose2D& h = frame_spec.humanoid_pose;
      const Pose2D truth{h.x + std::cos(h.theta) * centroid.x() - std::sin(h.theta) * centroid.y(),
                         h.y + std::sin(h.theta) * centroid.x() + std::cos(h.theta) * centroid.y(),
                         h.theta};
      theta_error_captured.push_back(std::abs(AngleDiff(pa.theta, truth.theta)));
      theta_error_generated.push_back(std::abs(AngleDiff(pb.theta, truth.theta)));
      pos_error_captured.push_back(std::hypot(pa.x - truth.x, pa.y - truth.y));
      pos_error_generated.push_back(std::hypot(pb.x - truth.x, pb.y - truth.y));
    }
  }
  std::cout << "median |dtheta| " << RadToDeg(Median(dtheta)) << " deg, median |dpos| "
            << Median(dpos) * 1000.0 << " mm over " << dtheta.size() << " frames\n";
  std::cout << "against the truth: captured template median |theta error| "
            << RadToDeg(Median(theta_error_captured)) << " deg, position "
            << Median(pos_error_captured) * 1000.0 << " mm; generated "
            << RadToDeg(Median(theta_error_generated)) << " deg, "
            << Median(pos_error_generated) * 1000.0 << " mm\n";
  EXPECT_LE(Median(dtheta), DegToRad(2.0));
  EXPECT_LE(Median(dpos), 0.005);
}

}  // namespace
}  // namespace hpose
