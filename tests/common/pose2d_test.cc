#include "core/common/pose2d.h"

#include <gtest/gtest.h>

namespace hpose {
namespace {

TEST(NormalizeAngleTest, WrapsIntoHalfOpenInterval) {
  EXPECT_DOUBLE_EQ(NormalizeAngle(kPi), kPi);
  EXPECT_DOUBLE_EQ(NormalizeAngle(-kPi), kPi);
  EXPECT_NEAR(NormalizeAngle(3 * kPi), kPi, 1e-12);
  EXPECT_NEAR(NormalizeAngle(DegToRad(370)), DegToRad(10), 1e-12);
  EXPECT_NEAR(NormalizeAngle(DegToRad(-190)), DegToRad(170), 1e-12);
  EXPECT_NEAR(AngleDiff(DegToRad(179), DegToRad(-179)), DegToRad(-2), 1e-12);
}

TEST(Pose2DTest, IsometryMapsRobotFrameToGround) {
  const Pose2D pose{1.0, 2.0, kPi / 2};
  const Eigen::Vector3d p = pose.ToIsometry() * Eigen::Vector3d(1, 0, 0.5);
  EXPECT_NEAR(p.x(), 1.0, 1e-12);
  EXPECT_NEAR(p.y(), 3.0, 1e-12);
  EXPECT_NEAR(p.z(), 0.5, 1e-12);
}

}  // namespace
}  // namespace hpose
