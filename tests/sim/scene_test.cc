#include "core/sim/scene.h"

#include <cmath>

#include <gtest/gtest.h>

namespace hpose {
namespace {

Scene SceneWithHumanoid(const Pose2D& pose) {
  Scene scene;
  const auto model = HumanoidModel::FromPreset("standing");
  EXPECT_TRUE(model.ok());
  EXPECT_TRUE(scene.AddHumanoid(*model, pose, "standing").ok());
  return scene;
}

double SegmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& b) {
  const double s = std::clamp(p.dot(b) / b.squaredNorm(), 0.0, 1.0);
  return (p - s * b).norm();
}

TEST(SceneTest, RandomClutterIsReproducibleAndKeepsClearOfTheHumanoid) {
  const Pose2D pose{1.5, 0.2, 0.3};
  Scene a = SceneWithHumanoid(pose);
  Scene b = SceneWithHumanoid(pose);
  Scene c = SceneWithHumanoid(pose);
  const ClutterOptions options;
  ASSERT_TRUE(a.AddRandomClutter(8, 42, options).ok());
  ASSERT_TRUE(b.AddRandomClutter(8, 42, options).ok());
  ASSERT_TRUE(c.AddRandomClutter(8, 43, options).ok());
  ASSERT_EQ(a.clutter().size(), 8u);
  EXPECT_EQ(a.clutter().front().shape, PrimitiveShape::kSphere);  // the ball.
  bool differs = false;
  const HumanoidModel& model = a.humanoids().front().model;
  const double humanoid_radius =
      std::max(model.bounds().min().head<2>().norm(), model.bounds().max().head<2>().norm());
  for (size_t i = 0; i < a.clutter().size(); ++i) {
    const Primitive& p = a.clutter()[i];
    EXPECT_TRUE(p.parent_from_local.isApprox(b.clutter()[i].parent_from_local)) << i;
    EXPECT_TRUE(p.half_size.isApprox(b.clutter()[i].half_size)) << i;
    differs = differs || !p.parent_from_local.isApprox(c.clutter()[i].parent_from_local);
    // Standing on the floor, in front of the sensor, within range and field of view.
    const Eigen::AlignedBox3d box = p.Bounds();
    EXPECT_NEAR(box.min().z(), 0.0, 1e-9) << p.name;
    const Eigen::Vector2d centre = p.parent_from_local.translation().head<2>();
    EXPECT_GE(centre.norm(), options.min_distance_m - 1e-9);
    EXPECT_LE(centre.norm(), options.max_distance_m + 1e-9);
    EXPECT_LE(std::abs(std::atan2(centre.y(), centre.x())), options.half_fov_rad + 1e-9);
    // Footprints never overlap the humanoid's, nor block the sensor's view of it.
    const double radius =
        std::max((box.min().head<2>() - centre).norm(), (box.max().head<2>() - centre).norm());
    EXPECT_GE((centre - Eigen::Vector2d(pose.x, pose.y)).norm(), radius + humanoid_radius);
    EXPECT_GE(SegmentDistance(centre, Eigen::Vector2d(pose.x, pose.y)), radius + humanoid_radius);
    for (size_t k = 0; k < i; ++k) {
      const Eigen::Vector2d other = a.clutter()[k].parent_from_local.translation().head<2>();
      EXPECT_GT((centre - other).norm(), options.clearance_m) << p.name;
    }
  }
  EXPECT_TRUE(differs);
}

TEST(SceneTest, ObjectsAreInTheGroundFrame) {
  const Pose2D pose{2.0, -0.5, 1.2};
  Scene scene = SceneWithHumanoid(pose);
  const auto objects = scene.ObjectsInGround();
  ASSERT_EQ(objects.size(), 1u);
  const HumanoidModel& model = scene.humanoids().front().model;
  ASSERT_EQ(objects[0].size(), model.primitives().size());
  for (size_t i = 0; i < objects[0].size(); ++i) {
    const Eigen::Vector3d expected =
        pose.ToIsometry() * model.primitives()[i].parent_from_local.translation();
    EXPECT_TRUE(objects[0][i].parent_from_local.translation().isApprox(expected, 1e-12));
  }
}

TEST(SceneTest, CrowdedSceneFailsWithAReason) {
  Scene scene = SceneWithHumanoid({1.0, 0.0, 0.0});
  ClutterOptions tiny;
  tiny.min_distance_m = 0.9;
  tiny.max_distance_m = 1.1;
  tiny.half_fov_rad = 0.1;
  tiny.max_attempts_per_object = 200;
  const Status s = scene.AddRandomClutter(20, 1, tiny);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().code, ErrorCode::kFailedPrecondition);
  EXPECT_NE(s.error().message.find("of 20"), std::string::npos);
  EXPECT_FALSE(scene.AddRandomClutter(-1, 1).ok());
  EXPECT_FALSE(scene.AddRandomClutter(101, 1).ok());
}

TEST(SceneTest, RejectsNonFiniteInput) {
  Scene scene;
  const auto model = HumanoidModel::FromPreset("standing");
  ASSERT_TRUE(model.ok());
  EXPECT_FALSE(scene.AddHumanoid(*model, {std::nan(""), 0.0, 0.0}).ok());
  EXPECT_FALSE(scene.AddClutter(Primitive::Sphere("ball", -0.1, Eigen::Vector3d(1, 0, 0.1))).ok());
  EXPECT_FALSE(
      scene.AddClutter(Primitive::Sphere("ball", 0.1, Eigen::Vector3d(std::nan(""), 0, 0))).ok());
  EXPECT_TRUE(scene.AddClutter(Primitive::Sphere("ball", 0.1, Eigen::Vector3d(1, 0, 0.1))).ok());
  EXPECT_EQ(scene.clutter().size(), 1u);
}

}  // namespace
}  // namespace hpose
