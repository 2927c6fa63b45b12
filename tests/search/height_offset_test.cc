// A robot that stands lower or higher than its template (bent knees, a mat) is found by the
// searches again with the templates a voxel lower and higher, only when nothing passed on the
// floor; a tracked stream starts where the previous frame's humanoid stood.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/search/estimator.h"
#include "core/search/pose_tracker.h"
#include "core/sim/frame_simulator.h"
#include "core/sim/humanoid_model.h"
#include "core/templates/voxel_template.h"

namespace hpose {
namespace {

constexpr double kEdge = 0.016;

// The template of a joint preset made `dz` metres above the body's own floor: a robot seen with
// it stands that much lower than its template (dz > 0, as with bent knees) or higher (dz < 0;
// what would lie below the floor is left out, as a floor hides a robot's soles).
VoxelTemplate OffsetTemplate(const std::string& preset, double dz) {
  const HumanoidModel model =
      *HumanoidModel::FromPreset(preset, *HumanoidDimensions::Variant("nao"));
  const std::vector<Eigen::Vector3f> surface = *model.SampleSurface(0.004);
  std::vector<Eigen::Vector3f> points;
  for (const Eigen::Vector3f& p : surface) {
    const Eigen::Vector3f q = p + Eigen::Vector3f(0.0f, 0.0f, static_cast<float>(dz));
    if (q.z() >= 0.0f) points.push_back(q);
  }
  return *MakeTemplateFromPoints(points, preset, kEdge, preset, "test");
}

SimulatedFrame Frame(const Pose2D& pose, std::uint64_t seed) {
  FrameSpec spec;
  spec.humanoid_pose = pose;
  spec.clutter = 3;
  spec.seed = seed;
  spec.sensor_height_m = 0.9;
  spec.sensor_pitch_rad = DegToRad(20.0);
  Result<SimulatedFrame> frame = SimulateFrame(spec);
  EXPECT_TRUE(frame.ok()) << frame.error().ToString();
  return std::move(frame).value();
}

std::unique_ptr<Estimator> MakeEstimator(double dz, int offsets) {
  EstimatorOptions options = DefaultEstimatorOptions();
  options.height_offset_voxels = offsets;
  Result<std::unique_ptr<Estimator>> e = Estimator::Create(
      options, {OffsetTemplate("standing", dz), OffsetTemplate("right_arm_raised", dz)});
  EXPECT_TRUE(e.ok()) << e.error().ToString();
  return std::move(e).value();
}

double HeadingErrorDeg(const Candidate& c, const Pose2D& truth) {
  return std::abs(RadToDeg(AngleDiff(c.pose.theta, truth.theta)));
}

double PositionError(const Candidate& c, const Pose2D& truth) {
  return std::hypot(c.pose.x - truth.x, c.pose.y - truth.y);
}

// 28 mm: a search on the floor misses such a robot (its score falls by about a point a
// millimetre), one voxel lower or higher leaves 12 mm, which a search takes in its stride.
TEST(HeightOffsetTest, ARobotLowerOrHigherThanItsTemplateIsFoundWithTheTemplateMoved) {
  const Intrinsics intrinsics = FrameSpec().intrinsics;
  const std::vector<Pose2D> poses = {{1.4, 0.1, DegToRad(30.0)}, {2.2, -0.2, DegToRad(-120.0)}};
  for (const double dz : {0.028, -0.028}) {
    const auto on_floor_only = MakeEstimator(dz, 0);
    const auto moved = MakeEstimator(dz, 1);
    for (size_t k = 0; k < poses.size(); ++k) {
      SCOPED_TRACE("template " + std::to_string(1000 * dz) + " mm above, frame " +
                   std::to_string(k));
      const SimulatedFrame frame = Frame(poses[k], 70 + k);
      const Estimate missed = *on_floor_only->EstimateDepth(frame.depth, intrinsics);
      EXPECT_TRUE(missed.Humanoids().empty());
      EXPECT_EQ(missed.height_passes, 1);
      const Estimate found = *moved->EstimateDepth(frame.depth, intrinsics);
      const HumanoidView humans = found.Humanoids();
      ASSERT_EQ(humans.size(), 1u);
      const Candidate& c = humans.front().best;
      // The template a voxel lower when it was made higher than the robot, and the other way.
      EXPECT_DOUBLE_EQ(c.height_offset_m, dz > 0.0 ? -kEdge : kEdge);
      EXPECT_EQ(found.height_passes, 3);
      EXPECT_LT(HeadingErrorDeg(c, poses[k]), 3.0);
      EXPECT_LT(PositionError(c, poses[k]), 0.02);
      // Every cluster was searched again with the templates moved.
      for (const Candidate& other : found.candidates) {
        EXPECT_DOUBLE_EQ(other.height_offset_m, c.height_offset_m);
      }
    }
  }
}

// A robot that passes with its template on the floor is searched once, exactly as without the
// option.
TEST(HeightOffsetTest, AFrameWhoseRobotPassesOnTheFloorIsSearchedOnce) {
  const Intrinsics intrinsics = FrameSpec().intrinsics;
  const auto plain = MakeEstimator(0.0, 0);
  const auto moved = MakeEstimator(0.0, 2);
  const Pose2D truth{1.8, 0.15, DegToRad(75.0)};
  const SimulatedFrame frame = Frame(truth, 5);
  const Estimate a = *plain->EstimateDepth(frame.depth, intrinsics);
  const Estimate b = *moved->EstimateDepth(frame.depth, intrinsics);
  ASSERT_FALSE(b.Humanoids().empty());
  EXPECT_EQ(b.height_passes, 1);
  ASSERT_EQ(a.candidates.size(), b.candidates.size());
  for (size_t i = 0; i < a.candidates.size(); ++i) {
    EXPECT_EQ(a.candidates[i].pose.x, b.candidates[i].pose.x);
    EXPECT_EQ(a.candidates[i].pose.y, b.candidates[i].pose.y);
    EXPECT_EQ(a.candidates[i].pose.theta, b.candidates[i].pose.theta);
    EXPECT_EQ(a.candidates[i].score, b.candidates[i].score);
    EXPECT_EQ(b.candidates[i].height_offset_m, 0.0);
  }
  EXPECT_LT(HeadingErrorDeg(b.Humanoids().front().best, truth), 3.0);
}

// In a stream, the frames after the first start at the offset the robot was found at: searched
// once, at that offset, as long as the robot keeps passing there.
TEST(HeightOffsetTest, ATrackedStreamStartsWhereTheRobotStoodBefore) {
  const Intrinsics intrinsics = FrameSpec().intrinsics;
  const auto estimator = MakeEstimator(0.028, 1);
  PoseTracker tracker(estimator.get());
  for (int k = 0; k < 3; ++k) {
    SCOPED_TRACE("frame " + std::to_string(k));
    const Pose2D truth{1.5 + 0.05 * k, -0.1, DegToRad(-60.0 + 5.0 * k)};
    const Estimate e = *tracker.EstimateDepth(Frame(truth, 90 + k).depth, intrinsics);
    const HumanoidView humans = e.Humanoids();
    ASSERT_EQ(humans.size(), 1u);
    EXPECT_DOUBLE_EQ(humans.front().best.height_offset_m, -kEdge);
    EXPECT_EQ(e.height_passes, k == 0 ? 3 : 1);
    EXPECT_LT(HeadingErrorDeg(humans.front().best, truth), 3.0);
    ASSERT_TRUE(tracker.prior().has_value());
    EXPECT_DOUBLE_EQ(tracker.prior()->height_offset_m, -kEdge);
  }
}

SimulatedFrame EmptyFrame(std::uint64_t seed) {
  FrameSpec spec;
  spec.humanoid_pose = Pose2D{15.0, 0.0, 0.0};  // out of range: the floor and clutter only.
  spec.clutter = 2;
  spec.seed = seed;
  Result<SimulatedFrame> frame = SimulateFrame(spec);
  EXPECT_TRUE(frame.ok()) << frame.error().ToString();
  return std::move(frame).value();
}

// A stream that has lost its robot moves the templates off the floor to every offset in its
// first frame without one, then to one offset a frame: each frame after the first searches
// twice (on the floor, then at its offset), not five times in one frame of four.
TEST(HeightOffsetTest, AStreamWithoutItsRobotTriesOneOffsetAFrame) {
  const Intrinsics intrinsics = FrameSpec().intrinsics;
  const auto estimator = MakeEstimator(0.0, 2);
  PoseTracker tracker(estimator.get());
  for (int k = 0; k < 6; ++k) {
    SCOPED_TRACE("frame " + std::to_string(k));
    const Estimate e = *tracker.EstimateDepth(EmptyFrame(120 + k).depth, intrinsics);
    ASSERT_TRUE(e.Humanoids().empty());
    // On the floor, then one and two voxels lower and higher: five searches; then two.
    EXPECT_EQ(e.height_passes, k == 0 ? 5 : 2);
  }
}

// The offsets taken in turn are one voxel lower, one higher, two lower, two higher, and around
// again: a robot 28 mm lower than its template passes a voxel or two lower, never higher.
TEST(HeightOffsetTest, OneOffsetInTurnTakesTheOffsetsInTheirOrder) {
  const Intrinsics intrinsics = FrameSpec().intrinsics;
  const auto estimator = MakeEstimator(0.028, 2);
  const Pose2D truth{1.6, 0.1, DegToRad(40.0)};
  const SimulatedFrame frame = Frame(truth, 130);
  const double expected[] = {-kEdge, 0.0, -2.0 * kEdge, 0.0, -kEdge};  // 0.0: nothing passes.
  for (int turn = 0; turn < 5; ++turn) {
    SCOPED_TRACE("turn " + std::to_string(turn));
    FramePrior prior;
    prior.height_offset_turn = turn;
    const Estimate e = *estimator->EstimateDepth(frame.depth, intrinsics, &prior);
    EXPECT_EQ(e.height_passes, 2);
    const HumanoidView humans = e.Humanoids();
    if (expected[turn] == 0.0) {
      EXPECT_TRUE(humans.empty());
      continue;
    }
    ASSERT_EQ(humans.size(), 1u);
    EXPECT_DOUBLE_EQ(humans.front().best.height_offset_m, expected[turn]);
    EXPECT_LT(HeadingErrorDeg(humans.front().best, truth), 3.0);
  }
}

// A robot lower than its template walking into a stream that has lost it is found when its
// offset's turn comes, and from then on tracked there, searched once a frame.
TEST(HeightOffsetTest, ALostStreamFindsALowerRobotWhenItsOffsetsTurnComes) {
  const Intrinsics intrinsics = FrameSpec().intrinsics;
  const auto estimator = MakeEstimator(0.028, 2);
  PoseTracker tracker(estimator.get());
  // Frames 0 and 1 without it, seen from the same mount (every offset, then one voxel lower);
  // from frame 2 on it stands there: frame 2 takes one voxel higher (missed), frame 3 two lower
  // (found).
  for (int k = 0; k < 6; ++k) {
    SCOPED_TRACE("frame " + std::to_string(k));
    const Pose2D truth{1.5 + 0.03 * k, -0.1, DegToRad(-50.0 + 4.0 * k)};
    const Pose2D out_of_range{15.0, 0.0, 0.0};
    const SimulatedFrame frame = Frame(k < 2 ? out_of_range : truth, 140 + k);
    const Estimate e = *tracker.EstimateDepth(frame.depth, intrinsics);
    const HumanoidView humans = e.Humanoids();
    EXPECT_EQ(e.height_passes, k == 0 ? 5 : k <= 3 ? 2 : 1);
    if (k < 3) {
      EXPECT_TRUE(humans.empty());
      continue;
    }
    ASSERT_EQ(humans.size(), 1u);
    EXPECT_DOUBLE_EQ(humans.front().best.height_offset_m, -2.0 * kEdge);
    EXPECT_LT(HeadingErrorDeg(humans.front().best, truth), 3.0);
  }
}

TEST(HeightOffsetTest, OffsetsOutsideTheirRangeAreRefused) {
  for (const int offsets : {-1, 9}) {
    EstimatorOptions options = DefaultEstimatorOptions();
    options.height_offset_voxels = offsets;
    const Result<std::unique_ptr<Estimator>> e =
        Estimator::Create(options, {OffsetTemplate("standing", 0.0)});
    ASSERT_FALSE(e.ok());
    EXPECT_NE(e.error().message.find("height_offset_voxels"), std::string::npos);
  }
}

}  // namespace
}  // namespace hpose
