// Tracking seeds each frame's search with the previous pose and changes no result: the same
// candidates as a cold search, and a robot carried away is found in the same frame.
#include "core/search/pose_tracker.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "core/sim/frame_simulator.h"
#include "core/sim/humanoid_model.h"
#include "tests/search/model_templates.h"

namespace hpose {
namespace {

using testing::ModelTemplate;

SimulatedFrame Frame(const Pose2D& pose, std::uint64_t seed, bool humanoid = true) {
  FrameSpec spec;
  spec.preset = "standing";
  spec.humanoid_pose = pose;
  spec.clutter = 3;
  spec.seed = seed;
  if (!humanoid) spec.humanoid_pose = Pose2D{30.0, 0.0, 0.0};  // out of range: floor only.
  return *SimulateFrame(spec);
}

// The same candidates; with `confirmed_differ`, a seeded frame's candidate that confirmed the
// previous heading (Candidate::heading_confirmed) has no runner-up where the cold one may.
void ExpectSameCandidates(const Estimate& a, const Estimate& b, int frame, bool confirmed_differ,
                          int* confirmed) {
  ASSERT_EQ(a.candidates.size(), b.candidates.size()) << "frame " << frame;
  for (size_t i = 0; i < a.candidates.size(); ++i) {
    const Candidate& x = a.candidates[i];
    const Candidate& y = b.candidates[i];
    EXPECT_EQ(x.template_name, y.template_name) << "frame " << frame;
    EXPECT_EQ(x.pose.x, y.pose.x) << "frame " << frame;
    EXPECT_EQ(x.pose.y, y.pose.y) << "frame " << frame;
    EXPECT_EQ(x.pose.theta, y.pose.theta) << "frame " << frame;
    EXPECT_EQ(x.score, y.score) << "frame " << frame;
    EXPECT_FALSE(x.heading_confirmed) << "a cold frame, frame " << frame;
    if (confirmed_differ && y.heading_confirmed) {
      ++*confirmed;
      EXPECT_FALSE(y.has_runner_up) << "frame " << frame;
      continue;
    }
    EXPECT_FALSE(y.heading_confirmed) << "frame " << frame;
    EXPECT_EQ(x.has_runner_up, y.has_runner_up) << "frame " << frame;
    EXPECT_EQ(x.runner_up_score, y.runner_up_score) << "frame " << frame;
  }
}

// Walking forward and turning, then carried 1.2 m to the side and turned, with the floor given
// (the sensor's true mount) so that cold and tracked frames share it exactly and only the
// seeding differs. The same optimum either way; the runner-up headings too when tracked frames
// never confirm the previous heading (tracked_heading_confirm_rad 0). Returns how many
// candidates confirmed it.
int SeededAgainstCold(double confirm_rad) {
  const std::vector<VoxelTemplate> tpls = {ModelTemplate("standing"),
                                           ModelTemplate("right_arm_raised")};
  EstimatorOptions options = DefaultEstimatorOptions();
  options.use_fixed_floor = true;
  options.fixed_floor = Frame({1.3, -0.2, 0.0}, 11).sensor_mount;
  options.tracked_heading_confirm_rad = confirm_rad;
  // Every template refined, as in a cold frame (tracked_templates_test covers the default).
  options.tracked_other_template_margin = -1.0;
  auto estimator = std::move(Estimator::Create(options, tpls).value());
  PoseTracker tracker(estimator.get());
  const Intrinsics intrinsics = FrameSpec().intrinsics;
  int tracked = 0, confirmed = 0;
  for (int k = 0; k < 4; ++k) {
    Pose2D truth{1.3 + 0.03 * k, -0.2 + 0.02 * k, DegToRad(40.0 + 4.0 * k)};
    if (k == 3) truth = Pose2D{2.2, 0.9, DegToRad(-100.0)};
    const SimulatedFrame frame = Frame(truth, 11);
    const Estimate cold = *estimator->EstimateDepth(frame.depth, intrinsics);
    const Estimate seeded = *tracker.EstimateDepth(frame.depth, intrinsics);
    EXPECT_FALSE(cold.tracking.prior_given);
    EXPECT_EQ(seeded.tracking.prior_given, k > 0) << k;
    const int confirmed_before = confirmed;
    ExpectSameCandidates(cold, seeded, k, confirm_rad > 0.0, &confirmed);
    if (!seeded.tracking.tracked) EXPECT_EQ(confirmed, confirmed_before) << "untracked frame " << k;
    tracked += seeded.tracking.tracked ? 1 : 0;
    if (k == 1 || k == 2) EXPECT_TRUE(seeded.tracking.tracked) << k;
    if (k == 3) EXPECT_FALSE(seeded.tracking.tracked) << "the prior lay on no cluster";
    EXPECT_FALSE(seeded.Humanoids().empty()) << k;
    if (seeded.Humanoids().empty()) continue;
    const Pose2D p = seeded.Humanoids().front().best.pose;
    EXPECT_LT(std::hypot(p.x - truth.x, p.y - truth.y), 0.05) << k;
    EXPECT_LT(std::abs(AngleDiff(p.theta, truth.theta)), DegToRad(10.0)) << k;
    EXPECT_TRUE(tracker.prior().has_value());
    if (tracker.prior()) EXPECT_EQ(tracker.prior()->pose.x, p.x);
  }
  EXPECT_EQ(tracked, 2);
  return confirmed;
}

TEST(PoseTrackerTest, SeededFramesEqualColdOnesAndAKidnappedRobotIsFoundAtOnce) {
  EXPECT_EQ(SeededAgainstCold(0.0), 0);
  // By default the frames that confirm the previous heading leave their runner-up unsearched:
  // at least the two tracked frames' humanoids.
  EXPECT_GE(SeededAgainstCold(DefaultEstimatorOptions().tracked_heading_confirm_rad), 2);
}

// With a fitted floor, the tracker keeps the first frame's floor while it fits: later frames
// of a fixed sensor reuse it (one ground frame for the whole stream), and poses stay right.
TEST(PoseTrackerTest, KeepsTheFloorOfAFixedSensor) {
  auto estimator =
      std::move(Estimator::Create(DefaultEstimatorOptions(), {ModelTemplate("standing")}).value());
  PoseTracker tracker(estimator.get());
  const Intrinsics intrinsics = FrameSpec().intrinsics;
  Eigen::Vector4d first_plane = Eigen::Vector4d::Zero();
  for (int k = 0; k < 3; ++k) {
    const Pose2D truth{1.4 + 0.05 * k, 0.1, DegToRad(10.0 * k)};
    const Estimate e = *tracker.EstimateDepth(Frame(truth, 30 + k).depth, intrinsics);
    EXPECT_EQ(e.tracking.floor_reused, k > 0) << k;
    if (k == 0) first_plane = e.floor.plane_sensor;
    if (k > 0) EXPECT_EQ(e.floor.plane_sensor, first_plane) << k;
    ASSERT_FALSE(e.Humanoids().empty()) << k;
    const Pose2D p = e.Humanoids().front().best.pose;
    EXPECT_LT(std::hypot(p.x - truth.x, p.y - truth.y), 0.03) << k;
  }
  tracker.Reset();
  const Estimate fresh = *tracker.EstimateDepth(Frame({1.5, 0.0, 0.0}, 40).depth, intrinsics);
  EXPECT_FALSE(fresh.tracking.floor_reused);
  EXPECT_FALSE(fresh.tracking.prior_given);
}

// A robot turned about in place between two frames (picked up and put down facing the other
// way while the stream ran on) is seen facing its new way in the first frame that shows it:
// the search is still seeded there (same spot), but the depth images decide front from back in
// every frame, and the previous heading only breaks ties a frame cannot decide.
TEST(PoseTrackerTest, ARobotTurnedAboutInPlaceIsSeenTurnedAtOnce) {
  auto estimator =
      std::move(Estimator::Create(DefaultEstimatorOptions(),
                                  {ModelTemplate("standing"), ModelTemplate("right_arm_raised")})
                    .value());
  const Intrinsics intrinsics = FrameSpec().intrinsics;
  for (const double heading_deg : {50.0, -100.0}) {
    PoseTracker tracker(estimator.get());
    for (int k = 0; k < 4; ++k) {
      const double turned = k >= 2 ? 180.0 : 0.0;
      const Pose2D truth{1.6, 0.1, NormalizeAngle(DegToRad(heading_deg + turned + 2.0 * k))};
      const Estimate e = *tracker.EstimateDepth(Frame(truth, 50 + k).depth, intrinsics);
      const std::vector<Detection> humans = e.Humanoids();
      ASSERT_FALSE(humans.empty()) << heading_deg << " frame " << k;
      const Candidate& c = humans.front().best;
      EXPECT_LT(std::abs(RadToDeg(AngleDiff(c.pose.theta, truth.theta))), 5.0)
          << heading_deg << " frame " << k << ": " << RadToDeg(c.pose.theta);
      if (k == 2) {
        EXPECT_TRUE(e.tracking.tracked) << heading_deg;
        EXPECT_FALSE(c.heading_from_prior) << heading_deg;
      }
    }
  }
}

TEST(PoseTrackerTest, AFrameWithoutHumanoidDropsThePrior) {
  auto estimator =
      std::move(Estimator::Create(DefaultEstimatorOptions(), {ModelTemplate("standing")}).value());
  PoseTracker tracker(estimator.get());
  const Intrinsics intrinsics = FrameSpec().intrinsics;
  ASSERT_TRUE(tracker.EstimateDepth(Frame({1.5, 0.0, 0.3}, 5).depth, intrinsics).ok());
  ASSERT_TRUE(tracker.prior().has_value());
  const Estimate empty = *tracker.EstimateDepth(Frame({1.5, 0.0, 0.3}, 5, false).depth, intrinsics);
  EXPECT_TRUE(empty.Humanoids().empty());
  EXPECT_FALSE(tracker.prior().has_value());
  DepthImage bad;
  EXPECT_FALSE(tracker.EstimateDepth(bad, intrinsics).ok());
  EXPECT_FALSE(tracker.prior().has_value());
}

}  // namespace
}  // namespace hpose
