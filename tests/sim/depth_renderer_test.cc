#include "core/sim/depth_renderer.h"

#include <cmath>

#include <gtest/gtest.h>

#include "core/depth/depth_to_cloud.h"

namespace hpose {
namespace {

DepthRenderer MakeRenderer(double height, double pitch, double roll, int width = 640,
                           int height_px = 480) {
  Result<DepthRenderer> r =
      DepthRenderer::Create(Intrinsics::KinectV1(width, height_px),
                            FloorEstimate::FromHeightPitchRoll(height, pitch, roll));
  EXPECT_TRUE(r.ok());
  return *r;
}

Eigen::Vector3d PixelRay(const Intrinsics& k, int u, int v) {
  return Eigen::Vector3d((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0).normalized();
}

TEST(DepthRendererTest, FloorPixelsGiveTheFloorDistance) {
  const double h = 0.34;
  const DepthRenderer renderer = MakeRenderer(h, 0.0, 0.0);
  const Scene scene;  // floor only.
  const DepthImage image = renderer.Render(scene);
  const Intrinsics& k = renderer.intrinsics();
  int checked = 0;
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; u += 7) {
      const double below = v - k.cy;  // level sensor: the floor is at y = h.
      if (below <= 0.0) {
        EXPECT_EQ(image.at(u, v), 0) << u << "," << v;  // at or above the horizon.
        continue;
      }
      const double z = h * k.fy / below;
      if (z > 65.0) continue;
      EXPECT_NEAR(image.at(u, v), z * 1000.0, 0.5 + 1e-6) << u << "," << v;
      ++checked;
    }
  }
  EXPECT_GT(checked, 10000);
}

TEST(DepthRendererTest, BoxFaceHasTheAnalyticDepthFromATiltedSensor) {
  const double h = 0.5;
  const double pitch = 0.15;
  const double roll = 0.05;
  const DepthRenderer renderer = MakeRenderer(h, pitch, roll);
  Scene scene;
  // A wide wall-like box whose front face is the plane x = 1.8 of the ground frame.
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(2.0, 0.0, 0.5);
  ASSERT_TRUE(scene.AddClutter(Primitive::Box("wall", Eigen::Vector3d(0.4, 3.0, 1.0), pose)).ok());
  const DepthImage image = renderer.Render(scene);
  const Intrinsics& k = renderer.intrinsics();
  const Eigen::Isometry3d& ground_from_sensor = renderer.sensor_mount().ground_from_sensor;
  int on_face = 0;
  for (int v = 0; v < k.height; v += 5) {
    for (int u = 0; u < k.width; u += 5) {
      const Eigen::Vector3d dir = PixelRay(k, u, v);
      const Eigen::Vector3d d_g = ground_from_sensor.linear() * dir;
      const Eigen::Vector3d o_g = ground_from_sensor.translation();
      if (d_g.x() <= 0.0) continue;
      const double t = (1.8 - o_g.x()) / d_g.x();
      const Eigen::Vector3d p = o_g + t * d_g;
      // Only pixels clearly inside the face (away from its edges and the floor line).
      if (p.z() < 0.02 || p.z() > 0.98 || std::abs(p.y()) > 1.48) continue;
      EXPECT_NEAR(image.at(u, v), t * dir.z() * 1000.0, 0.5 + 1e-6) << u << "," << v;
      ++on_face;
    }
  }
  EXPECT_GT(on_face, 3000);
}

TEST(DepthRendererTest, CloudOfANoiselessRenderPutsTheFloorAtZeroHeight) {
  const DepthRenderer renderer = MakeRenderer(0.6, 0.35, -0.08);
  const Scene scene;
  const DepthImage image = renderer.Render(scene);
  DepthToCloudOptions options;
  options.min_range_m = 0.1;
  options.max_range_m = 10.0;
  const Result<PointCloud> cloud = DepthToCloud(image, renderer.intrinsics(), options);
  ASSERT_TRUE(cloud.ok()) << cloud.error().ToString();
  ASSERT_GT(cloud->size(), 100000u);
  const FloorEstimate floor = FloorEstimate::FromHeightPitchRoll(0.6, 0.35, -0.08);
  for (const Eigen::Vector3f& p : cloud->points) {
    const Eigen::Vector3d g = floor.ground_from_sensor * p.cast<double>();
    ASSERT_NEAR(g.z(), 0.0, 0.002) << p.transpose();
    ASSERT_GT(g.x(), 0.0);
  }
}

TEST(DepthRendererTest, HumanoidAppearsWhereItStands) {
  const auto model = HumanoidModel::FromPreset("standing");
  ASSERT_TRUE(model.ok());
  Scene scene;
  const Pose2D pose{1.0, 0.0, 0.0};  // facing away from the sensor.
  ASSERT_TRUE(scene.AddHumanoid(*model, pose).ok());
  const DepthRenderer renderer = MakeRenderer(0.34, 0.0, 0.0);
  const DepthImage image = renderer.Render(scene);
  const Result<PointCloud> cloud = DepthToCloud(image, renderer.intrinsics());
  ASSERT_TRUE(cloud.ok());
  const Eigen::Isometry3d& ground_from_sensor = renderer.sensor_mount().ground_from_sensor;
  double top = 0.0;
  double nearest_x = 10.0;
  int body = 0;
  for (const Eigen::Vector3f& p : cloud->points) {
    const Eigen::Vector3d g = ground_from_sensor * p.cast<double>();
    if (g.z() < 0.01) continue;
    ++body;
    EXPECT_LT((g.head<2>() - Eigen::Vector2d(pose.x, pose.y)).norm(), 0.3);
    top = std::max(top, g.z());
    nearest_x = std::min(nearest_x, g.x());
  }
  EXPECT_GT(body, 10000);
  // Seen from 0.34 m high, the top of the head is hidden but the back of it is not.
  EXPECT_GT(top, model->Height() - 0.06);
  EXPECT_LE(top, model->Height() + 0.001);
  // The back-most point of the body faces the sensor.
  EXPECT_NEAR(nearest_x, pose.x + model->bounds().min().x(), 0.01);
}

TEST(DepthRendererTest, NoiseIsReproducibleBySeedAndRespectsTheRange) {
  const auto model = HumanoidModel::FromPreset("right_arm_raised");
  ASSERT_TRUE(model.ok());
  Scene scene;
  ASSERT_TRUE(scene.AddHumanoid(*model, {1.5, 0.1, 0.5}).ok());
  ASSERT_TRUE(scene.AddRandomClutter(5, 3).ok());
  const DepthRenderer renderer = MakeRenderer(0.34, 0.0, 0.0, 320, 240);
  const Result<KinectNoiseModel> noise = KinectNoiseModel::Create({});
  ASSERT_TRUE(noise.ok());
  const DepthImage a = renderer.Render(scene, &*noise, 5);
  const DepthImage b = renderer.Render(scene, &*noise, 5);
  const DepthImage c = renderer.Render(scene, &*noise, 6);
  const DepthImage ideal = renderer.Render(scene);
  EXPECT_EQ(a.mm, b.mm);
  EXPECT_NE(a.mm, c.mm);
  int valid = 0;
  int ideal_far = 0;
  for (size_t i = 0; i < a.mm.size(); ++i) {
    if (a.mm[i] != 0) {
      ++valid;
      EXPECT_GE(a.mm[i], 800);
      EXPECT_LE(a.mm[i], 4000);
    }
    ideal_far += ideal.mm[i] > 4000 ? 1 : 0;
  }
  EXPECT_GT(valid, 5000);
  EXPECT_GT(ideal_far, 0);  // there was something beyond 4 m to drop.
}

TEST(DepthRendererTest, GrazingFloorGivesNoReading) {
  // Level at 0.34 m: the floor is seen at more than 80 degrees incidence beyond about 1.93 m.
  const DepthRenderer renderer = MakeRenderer(0.34, 0.0, 0.0);
  KinectNoiseOptions options;
  options.noise_enabled = false;
  const Result<KinectNoiseModel> noise = KinectNoiseModel::Create(options);
  ASSERT_TRUE(noise.ok());
  const DepthImage image = renderer.Render(Scene(), &*noise, 1);
  const Intrinsics& k = renderer.intrinsics();
  const double limit_m = 0.34 / std::tan(kPi / 2.0 - options.max_incidence_rad);
  int near_valid = 0;
  for (int v = static_cast<int>(k.cy) + 1; v < k.height; ++v) {
    const int u = static_cast<int>(k.cx);
    const double z = 0.34 * k.fy / (v - k.cy);
    const double incidence = std::acos(PixelRay(k, u, v).y());
    if (incidence > options.max_incidence_rad + 1e-3) {
      EXPECT_EQ(image.at(u, v), 0) << v;
    } else if (incidence < options.max_incidence_rad - 1e-3 && z >= 0.8) {
      EXPECT_NEAR(image.at(u, v), z * 1000.0, 0.5 + 1e-6) << v;
      ++near_valid;
    }
  }
  EXPECT_GT(near_valid, 20);
  EXPECT_GT(limit_m, 1.5);
}

TEST(DepthRendererTest, RejectsBadSetups) {
  Intrinsics bad = Intrinsics::KinectV1();
  bad.fx = -1.0;
  EXPECT_FALSE(DepthRenderer::Create(bad, FloorEstimate::FromHeightPitchRoll(0.3, 0, 0)).ok());
  FloorEstimate below = FloorEstimate::FromHeightPitchRoll(0.3, 0, 0);
  below.ground_from_sensor.translation().z() = -0.1;
  EXPECT_FALSE(DepthRenderer::Create(Intrinsics::KinectV1(), below).ok());
}

}  // namespace
}  // namespace hpose
