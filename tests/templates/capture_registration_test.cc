// Templates from turntable / hand-turned captures: simulated captures with a known axis, robot
// placement and headings, registered by the same code the `template from-captures` command runs.
#include "core/templates/capture_registration.h"

#include <algorithm>
#include <cmath>
#include <iostream>

#include <gtest/gtest.h>

#include "core/depth/depth_to_cloud.h"
#include "core/sim/turntable_captures.h"
#include "core/templates/capture_template.h"
#include "core/templates/capture_views.h"

namespace hpose {
namespace {

std::vector<CaptureView> ToViews(const TurntableCaptures& captures, const Intrinsics& k) {
  std::vector<CaptureView> views;
  DepthToCloudOptions options;
  options.keep_organised = true;
  for (size_t i = 0; i < captures.depth.size(); ++i) {
    Result<PointCloud> cloud = DepthToCloud(captures.depth[i], k, options);
    EXPECT_TRUE(cloud.ok());
    views.push_back({"view_" + std::to_string(i) + ".png", *cloud});
  }
  return views;
}

CaptureViewOptions ViewOptions(const TurntableSpec& spec) {
  CaptureViewOptions o;
  o.table_height_m = spec.table_height_m;
  return o;
}

// Distance (m) at the true floor between the estimated axis and the true one, and the angle
// (rad) between their directions, both in the sensor frame.
std::pair<double, double> AxisError(const CaptureViews& views, const CaptureRegistration& reg,
                                    const TurntableSpec& spec, const FloorEstimate& truth) {
  const Eigen::Isometry3d sensor_from_est = views.floor.ground_from_sensor.inverse();
  const Eigen::Isometry3d sensor_from_true = truth.ground_from_sensor.inverse();
  const Eigen::Vector3d p_est =
      sensor_from_est * Eigen::Vector3d(reg.axis_ground.x(), reg.axis_ground.y(), 0.0);
  const Eigen::Vector3d d_est = reg.axis_direction_sensor.normalized();
  const Eigen::Vector3d p_true =
      sensor_from_true * Eigen::Vector3d(spec.axis_ground.x(), spec.axis_ground.y(), 0.0);
  const Eigen::Vector3d d_true = truth.plane_sensor.head<3>().normalized();
  // Where the estimated axis meets the true floor plane.
  const double t = -(d_true.dot(p_est) + truth.plane_sensor[3]) / d_true.dot(d_est);
  const Eigen::Vector3d meet = p_est + t * d_est;
  return {(meet - p_true).norm(), std::acos(std::clamp(d_est.dot(d_true), -1.0, 1.0))};
}

TEST(CaptureRegistrationTest, TurntableAxisRecoveredFromTwelveNoisyViews) {
  TurntableSpec spec;
  spec.axis_ground = Eigen::Vector2d(1.27, -0.06);  // unknown to the estimator.
  spec.robot_on_table = Pose2D{0.04, 0.03, 0.5};
  spec.clutter = 3;
  spec.seed = 7;
  Result<TurntableCaptures> captures = SimulateTurntableCaptures(spec);
  ASSERT_TRUE(captures.ok()) << captures.error().ToString();
  Result<CaptureViews> views =
      ExtractRobotViews(ToViews(*captures, spec.intrinsics), ViewOptions(spec));
  ASSERT_TRUE(views.ok()) << views.error().ToString();
  ASSERT_EQ(views->views.size(), 12u);
  CaptureRegistrationOptions options;
  for (int i = 0; i < spec.views; ++i) options.angles_rad.push_back(i * spec.step_rad);
  Result<CaptureRegistration> reg = RegisterCaptureViews(*views, options);
  ASSERT_TRUE(reg.ok()) << reg.error().ToString();
  const auto [distance, angle] = AxisError(*views, *reg, spec, captures->sensor_mount);
  std::cout << "axis error " << distance * 1000.0 << " mm, " << RadToDeg(angle) << " deg\n";
  for (const ViewResidual& r : reg->residuals) {
    std::cout << r.name << " rms " << r.rms_m * 1000.0 << " mm inliers " << r.inlier_fraction
              << "\n";
    EXPECT_TRUE(r.fits) << r.name;
  }
  EXPECT_LT(distance, 0.005);
  EXPECT_LT(angle, DegToRad(0.5));
}

}  // namespace
}  // namespace hpose
