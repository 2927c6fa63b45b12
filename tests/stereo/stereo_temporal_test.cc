#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "core/stereo/object_motion_detector.h"
#include "core/stereo/path_line_fit.h"
#include "core/stereo/stereo_tracker.h"

namespace hpose {
namespace {

TEST(ObjectMotionDetectorTest, StationaryNoiseIsNotMotionAndAKickIs) {
  ObjectMotionDetector det;
  std::mt19937 rng(1);
  std::normal_distribution<double> noise(0.0, 0.015);
  const double fps = 15.0;
  int i = 0;
  for (; i < 45; ++i) {  // 3 s at rest with 15 mm noise.
    EXPECT_FALSE(det.Update(i / fps, Eigen::Vector2d(0.2 + noise(rng), 0.1 + noise(rng))))
        << "frame " << i;
  }
  EXPECT_TRUE(det.has_reference());
  EXPECT_NEAR(det.reference_mean().x(), 0.2, 0.02);
  const double kick = i / fps;
  int detected_at = -1;
  for (; i < 75; ++i) {  // rolls at 0.4 m/s.
    const double t = i / fps;
    const bool moving = det.Update(t, Eigen::Vector2d(0.2, 0.1 - 0.4 * (t - kick)));
    if (moving && detected_at < 0) detected_at = i;
  }
  ASSERT_GE(detected_at, 0);
  // 100 mm at 0.4 m/s is 0.25 s, i.e. about 4 frames after the kick.
  EXPECT_LE(detected_at - static_cast<int>(kick * fps), 5);
  EXPECT_GE(detected_at - static_cast<int>(kick * fps), 3);
}

TEST(ObjectMotionDetectorTest, NeedsReferenceFramesAndResetsOnTimeGoingBack) {
  ObjectMotionDetector det;
  // A huge jump in the first half second cannot be judged: no frames 0.5-1.0 s old yet.
  EXPECT_FALSE(det.Update(0.0, {0, 0}));
  EXPECT_FALSE(det.Update(0.1, {5, 5}));
  EXPECT_FALSE(det.has_reference());
  for (int i = 0; i < 20; ++i) det.Update(0.2 + i / 15.0, {0, 0});
  EXPECT_TRUE(det.Update(1.6, {0.5, 0}));
  EXPECT_FALSE(det.Update(0.5, {0.5, 0}));  // earlier than the last: history cleared.
  EXPECT_FALSE(det.has_reference());
}

TEST(PathLineFitTest, RecoversLineAndClosestApproach) {
  std::vector<TimedPosition> s;
  for (int i = 0; i < 8; ++i) {
    const double t = 2.0 + i / 15.0;
    s.push_back({t, Eigen::Vector2d(0.3 - 0.1 * (t - 1.9), 0.2 - 0.4 * (t - 1.9))});
  }
  auto fit = FitPathLine(s, 1.9);
  ASSERT_TRUE(fit.ok());
  EXPECT_NEAR(fit->velocity_mps.x(), -0.1, 1e-9);
  EXPECT_NEAR(fit->velocity_mps.y(), -0.4, 1e-9);
  EXPECT_NEAR(fit->origin_m.x(), 0.3, 1e-9);
  EXPECT_NEAR(fit->origin_m.y(), 0.2, 1e-9);
  EXPECT_LT(fit->rms_residual_m, 1e-9);
  EXPECT_EQ(fit->frames, 8);
  // Point on the line 2 s after t0: the path passes through it then.
  const Eigen::Vector2d target(0.3 - 0.2, 0.2 - 0.8);
  const auto a = fit->ClosestApproach(target);
  EXPECT_NEAR(a.t_s, 3.9, 1e-9);
  EXPECT_NEAR(a.distance_m, 0.0, 1e-9);
  // A point 0.1 m to the side of the path: perpendicular distance.
  const Eigen::Vector2d normal = Eigen::Vector2d(0.4, -0.1).normalized();
  EXPECT_NEAR(fit->ClosestApproach(target + 0.1 * normal).distance_m, 0.1, 1e-9);
}

TEST(PathLineFitTest, NoisyFitAndBadInput) {
  std::mt19937 rng(2);
  std::normal_distribution<double> noise(0.0, 0.01);
  std::vector<TimedPosition> s;
  for (int i = 0; i < 8; ++i) {
    const double t = i / 15.0;
    s.push_back({t, Eigen::Vector2d(0.5 * t + noise(rng), -0.2 * t + noise(rng))});
  }
  auto fit = FitPathLine(s, 0.0);
  ASSERT_TRUE(fit.ok());
  EXPECT_NEAR(fit->velocity_mps.x(), 0.5, 0.1);
  EXPECT_NEAR(fit->velocity_mps.y(), -0.2, 0.1);
  EXPECT_GT(fit->rms_residual_m, 0.0);
  EXPECT_FALSE(FitPathLine({s[0]}, 0.0).ok());
  EXPECT_FALSE(FitPathLine({s[0], s[0]}, 0.0).ok());  // same time twice.
  std::vector<TimedPosition> bad = s;
  bad[3].position_m.x() = std::nan("");
  EXPECT_FALSE(FitPathLine(bad, 0.0).ok());
}

StereoFrameResult Frame(double t, const Pose2D& robot, const Eigen::Vector3d* ball) {
  StereoFrameResult f;
  f.timestamp_s = t;
  f.robot = robot;
  if (ball != nullptr) {
    f.object_in_world = f.object_in_camera = true;
    f.object_world_m = *ball;
  }
  return f;
}

TEST(StereoTrackerTest, AveragesTheLastEightRobotPosesWithCircularHeading) {
  StereoTracker tracker;
  StereoTrackState s;
  for (int i = 0; i < 10; ++i) {
    // Headings alternate around +-pi: the mean must be pi, not 0.
    const double theta = (i % 2 == 0) ? kPi - 0.02 : -kPi + 0.02;
    s = tracker.Update(Frame(i * 0.1, Pose2D{static_cast<double>(i), 2.0 * i, theta}, nullptr));
  }
  ASSERT_TRUE(s.robot_valid);
  EXPECT_EQ(s.robot_frames, 8);
  EXPECT_NEAR(s.robot_mean.x, (2 + 3 + 4 + 5 + 6 + 7 + 8 + 9) / 8.0, 1e-12);
  EXPECT_NEAR(s.robot_mean.y, 2 * (2 + 3 + 4 + 5 + 6 + 7 + 8 + 9) / 8.0, 1e-12);
  EXPECT_NEAR(std::abs(s.robot_mean.theta), kPi, 1e-9);
  // A rejected frame does not enter the average.
  StereoFrameResult rejected = Frame(1.1, Pose2D{100, 100, 0}, nullptr);
  rejected.status = StereoFrameStatus::kMissingLandmark;
  s = tracker.Update(rejected);
  EXPECT_NEAR(s.robot_mean.x, 5.5, 1e-12);
}

TEST(StereoTrackerTest, DetectsMotionAndFitsPathFromEightFramesAfterIt) {
  StereoTracker tracker;
  const double fps = 15.0, kick = 2.0;
  const Eigen::Vector2d v(-0.1, -0.45);
  StereoTrackState s;
  double detected = -1;
  int path_first_frame = -1;
  for (int i = 0; i < 60; ++i) {
    const double t = i / fps;
    const Eigen::Vector2d p = Eigen::Vector2d(0.3, 0.1) + v * std::max(0.0, t - kick);
    const Eigen::Vector3d ball(p.x(), p.y(), 0.035);
    s = tracker.Update(Frame(t, Pose2D{0, -1, kPi / 2}, &ball));
    if (t < kick) EXPECT_FALSE(s.object_moving) << t;
    if (s.object_moving && detected < 0) detected = t;
    if (s.path_valid && path_first_frame < 0) path_first_frame = i;
  }
  ASSERT_GT(detected, kick);
  EXPECT_LT(detected - kick, 0.4);
  ASSERT_GE(path_first_frame, 0);
  EXPECT_EQ(path_first_frame, static_cast<int>(std::lround(detected * fps)) + 7);
  ASSERT_TRUE(s.path_valid);
  EXPECT_NEAR(s.path.velocity_mps.x(), v.x(), 1e-9);
  EXPECT_NEAR(s.path.velocity_mps.y(), v.y(), 1e-9);
  // The path's prediction of where the ball will be.
  const Eigen::Vector2d later = s.path.PositionAt(kick + 1.5);
  EXPECT_NEAR(later.x(), 0.3 + v.x() * 1.5, 1e-9);
  EXPECT_NEAR(later.y(), 0.1 + v.y() * 1.5, 1e-9);
}

}  // namespace
}  // namespace hpose
