#include "core/stereo/world_from_ground_fit.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

namespace hpose {
namespace {

// A robot walking a loop in the world frame, seen by both estimators: the depth poses are the
// world poses moved into the ground frame by the inverse of `world_from_ground`, each with its
// own noise, and a few depth poses are gross outliers (another object taken for the robot).
std::vector<GroundWorldPair> Recording(const Pose2D& world_from_ground, double radius_m,
                                       int outliers, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> depth_noise(0.0, 0.015), stereo_noise(0.0, 0.02);
  std::normal_distribution<double> heading_noise(0.0, 0.03);
  const Eigen::Rotation2Dd r(world_from_ground.theta);
  const Eigen::Vector2d t(world_from_ground.x, world_from_ground.y);
  std::vector<GroundWorldPair> pairs;
  for (int i = 0; i < 80; ++i) {
    const double a = 2 * kPi * i / 80;
    const Eigen::Vector2d world(0.1 + radius_m * std::cos(a), -0.9 + 0.6 * radius_m * std::sin(a));
    const double heading = a + kPi / 2;
    const Eigen::Vector2d ground = r.inverse() * (world - t);
    GroundWorldPair p;
    p.timestamp_s = i / 15.0;
    p.world = Pose2D{world.x() + stereo_noise(rng), world.y() + stereo_noise(rng),
                     NormalizeAngle(heading + heading_noise(rng))};
    p.ground = Pose2D{ground.x() + depth_noise(rng), ground.y() + depth_noise(rng),
                      NormalizeAngle(heading - world_from_ground.theta + heading_noise(rng))};
    if (i % 13 == 5 && outliers-- > 0) p.ground.x += 0.4;
    pairs.push_back(p);
  }
  return pairs;
}

TEST(WorldFromGroundFitTest, RecoversASimulatedPlacementAndDropsOutliers) {
  const Pose2D truth{1.35, -0.42, DegToRad(143.0)};
  const auto pairs = Recording(truth, 0.5, 4, 7);
  auto fit = FitWorldFromGround(pairs);
  ASSERT_TRUE(fit.ok()) << fit.error().message;
  EXPECT_LT(std::hypot(fit->world_from_ground.x - truth.x, fit->world_from_ground.y - truth.y),
            0.02);
  EXPECT_LT(std::abs(AngleDiff(fit->world_from_ground.theta, truth.theta)), DegToRad(1.0));
  EXPECT_EQ(fit->pairs, 80);
  EXPECT_EQ(fit->inliers, 76);
  for (size_t i = 0; i < pairs.size(); ++i) {
    if (i % 13 == 5 && i < 13 * 4) EXPECT_FALSE(fit->inlier[i]) << i;
  }
  EXPECT_GT(fit->rms_m, 0.01);  // the noise is there...
  EXPECT_LT(fit->rms_m, 0.05);  // ...but no outlier is left.
  EXPECT_TRUE(fit->rotation_from_positions);
  EXPECT_NE(fit->observability.find("positions"), std::string::npos);
}

TEST(WorldFromGroundFitTest, StandingRobotGivesYawFromHeadingsAndSaysSo) {
  const Pose2D truth{0.3, 0.8, DegToRad(-60.0)};
  const auto pairs = Recording(truth, 0.01, 0, 9);
  auto fit = FitWorldFromGround(pairs);
  ASSERT_TRUE(fit.ok());
  EXPECT_FALSE(fit->rotation_from_positions);
  EXPECT_NE(fit->observability.find("headings"), std::string::npos);
  EXPECT_LT(std::abs(AngleDiff(fit->world_from_ground.theta, truth.theta)), DegToRad(2.0));
}

TEST(WorldFromGroundFitTest, TooFewOrBadPairsFail) {
  EXPECT_EQ(FitWorldFromGround({}).error().code, ErrorCode::kInvalidArgument);
  auto pairs = Recording(Pose2D{0, 0, 0}, 0.5, 0, 1);
  pairs.resize(5);
  pairs[2].world.x = std::nan("");
  auto fit = FitWorldFromGround(pairs);
  ASSERT_FALSE(fit.ok());
  EXPECT_NE(fit.error().message.find("pair 2"), std::string::npos);
  // Finite but no robot's: a position of 1e300 m (it fitted an x of -2.5e299 m before).
  pairs[2].world.x = 1.0;
  ASSERT_TRUE(FitWorldFromGround(pairs).ok());
  pairs[3].ground.x = 1e300;
  fit = FitWorldFromGround(pairs);
  ASSERT_FALSE(fit.ok());
  EXPECT_NE(fit.error().message.find("pair 3 has a position 1e+300 m"), std::string::npos)
      << fit.error().message;
  pairs[3].ground.x = 1.0;
  pairs[4].world.theta = -1e6;
  fit = FitWorldFromGround(pairs);
  ASSERT_FALSE(fit.ok());
  EXPECT_NE(fit.error().message.find("heading of 1e+06 rad"), std::string::npos)
      << fit.error().message;
}

// Each depth pose takes the stereo pose nearest in time, within the tolerance only; the
// stereo poses may come in any order and at another rate.
TEST(WorldFromGroundFitTest, PairsPosesByNearestTime) {
  std::vector<TimedPose> world;
  for (int i = 9; i >= 0; --i) world.push_back({0.1 * i, Pose2D{double(i), 0.0, 0.0}});
  const std::vector<TimedPose> ground = {
      {-0.5, Pose2D{-1, 0, 0}},                           // before every stereo pose.
      {0.0, Pose2D{0, 1, 0}},   {0.26, Pose2D{1, 1, 0}},  // 0.3 is nearer than 0.2.
      {0.34, Pose2D{2, 1, 0}},                            // 0.3 again.
      {0.62, Pose2D{3, 1, 0}},  {0.94, Pose2D{4, 1, 0}},  // 0.04 after the last.
      {1.2, Pose2D{5, 1, 0}}};                            // after every stereo pose.
  const auto pairs = PairPosesByTime(ground, world, 0.05);
  ASSERT_EQ(pairs.size(), 5u);
  const double expected_world_x[] = {0, 3, 3, 6, 9};
  const double expected_t[] = {0.0, 0.26, 0.34, 0.62, 0.94};
  for (size_t i = 0; i < pairs.size(); ++i) {
    EXPECT_DOUBLE_EQ(pairs[i].timestamp_s, expected_t[i]);
    EXPECT_DOUBLE_EQ(pairs[i].ground.x, static_cast<double>(i));
    EXPECT_DOUBLE_EQ(pairs[i].world.x, expected_world_x[i]);
  }
  // A tighter tolerance drops the pairs 40 ms apart; none at all without stereo poses.
  EXPECT_EQ(PairPosesByTime(ground, world, 0.03).size(), 2u);
  EXPECT_TRUE(PairPosesByTime(ground, {}, 1.0).empty());
}

}  // namespace
}  // namespace hpose
