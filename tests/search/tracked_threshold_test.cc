// Hysteresis for a tracked humanoid (EstimatorOptions::tracked_score_threshold): the cluster the
// previous frame's humanoid stood on passes from the lower score when none of its templates
// reaches score_threshold, so a humanoid walking away stays found; every other cluster still
// needs the full score, and frames whose humanoid passes are searched as without it.
#include <cmath>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "core/search/estimator.h"
#include "core/search/pose_tracker.h"
#include "core/sim/frame_simulator.h"
#include "tests/search/far_nao_scene.h"

namespace hpose {
namespace {

// The far Nao's frame with one score threshold at every range: the far clusters' lower one
// would find this robot cold (far_threshold_test.cc).
struct Fixture : testing::FarNaoFrame {
  EstimatorOptions Options() const {
    EstimatorOptions o = FarNaoFrame::Options();
    o.far_score_ratio = 1.0;
    return o;
  }
  // Where the previous frame saw the robot: 3 cm and 2 degrees off this frame's pose.
  FramePrior Prior(double score) const {
    FramePrior p;
    p.has_pose = true;
    p.template_name = "standing";
    p.pose = Pose2D{spec.humanoid_pose.x - 0.03, spec.humanoid_pose.y,
                    spec.humanoid_pose.theta - DegToRad(2.0)};
    p.score = score;
    return p;
  }
};

void ExpectSameCandidates(const Estimate& a, const Estimate& b) {
  ASSERT_EQ(a.candidates.size(), b.candidates.size());
  for (size_t i = 0; i < a.candidates.size(); ++i) {
    const Candidate& x = a.candidates[i];
    const Candidate& y = b.candidates[i];
    EXPECT_EQ(x.template_name, y.template_name) << i;
    EXPECT_EQ(x.cluster_index, y.cluster_index) << i;
    EXPECT_EQ(x.pose.x, y.pose.x) << i;
    EXPECT_EQ(x.pose.y, y.pose.y) << i;
    EXPECT_EQ(x.pose.theta, y.pose.theta) << i;
    EXPECT_EQ(x.score, y.score) << i;
    EXPECT_EQ(x.stopped_below_threshold, y.stopped_below_threshold) << i;
  }
  ASSERT_EQ(a.detections.size(), b.detections.size());
  for (size_t i = 0; i < a.detections.size(); ++i) {
    EXPECT_EQ(a.detections[i].is_humanoid, b.detections[i].is_humanoid) << i;
    EXPECT_EQ(a.detections[i].score_threshold, b.detections[i].score_threshold) << i;
  }
}

TEST(TrackedThresholdTest, AFarHumanoidWhereTheLastFrameSawItStaysFound) {
  const Fixture f;
  const EstimatorOptions options = f.Options();
  // Cold, the humanoid's cluster does not reach the threshold.
  const Estimate cold = f.Run(options, nullptr);
  EXPECT_TRUE(cold.Humanoids().empty());
  for (const Candidate& c : cold.candidates) EXPECT_LT(c.score, options.score_threshold);

  const FramePrior prior = f.Prior(55.0);
  const Estimate held = f.Run(options, &prior);
  const std::vector<Detection> humans = held.Humanoids();
  ASSERT_EQ(humans.size(), 1u);
  const Detection& d = humans.front();
  EXPECT_TRUE(f.NearTruth(d)) << d.best.pose.x << " " << d.best.pose.y << " "
                              << RadToDeg(d.best.pose.theta);
  EXPECT_GE(d.best.score, options.tracked_score_threshold);
  EXPECT_LT(d.best.score, options.score_threshold);
  EXPECT_GE(d.best.fit.fit, options.min_humanoid_fit);
  EXPECT_EQ(d.score_threshold, options.tracked_score_threshold);
  // Every other cluster is held to the full threshold.
  int others = 0;
  for (const Detection& o : held.detections) {
    if (f.NearTruth(o)) continue;
    EXPECT_EQ(o.score_threshold, options.score_threshold);
    ++others;
  }
  EXPECT_GT(others, 0);  // the frame's clutter is searched too.

  // Without hysteresis the same prior finds nothing.
  EstimatorOptions off = options;
  off.tracked_score_threshold = options.score_threshold;
  const Estimate without_hysteresis = f.Run(off, &prior);
  EXPECT_TRUE(without_hysteresis.Humanoids().empty());

  // Searches that compute every optimum (nothing stopped) come to the same verdict and pose.
  EstimatorOptions full = options;
  full.stop_below_threshold = false;
  const Estimate full_search = f.Run(full, &prior);
  const HumanoidView full_humans = full_search.Humanoids();
  ASSERT_EQ(full_humans.size(), 1u);
  EXPECT_EQ(full_humans.front().best.pose.x, d.best.pose.x);
  EXPECT_EQ(full_humans.front().best.pose.y, d.best.pose.y);
  EXPECT_EQ(full_humans.front().best.pose.theta, d.best.pose.theta);
  EXPECT_EQ(full_humans.front().score_threshold, options.tracked_score_threshold);
}

TEST(TrackedThresholdTest, APriorStandingOnNoClusterChangesNothing) {
  const Fixture f;
  const EstimatorOptions options = f.Options();
  FramePrior prior = f.Prior(55.0);
  prior.pose = Pose2D{1.0, -1.2, 0.0};  // bare floor.
  ExpectSameCandidates(f.Run(options, &prior), f.Run(options, nullptr));
}

// A prior that itself passed by the lower threshold sends its cluster straight down to it: the
// same result as searching to the full threshold first and again to the lower one.
TEST(TrackedThresholdTest, StraightDownEqualsTwoPasses) {
  const Fixture f;
  const EstimatorOptions options = f.Options();
  const FramePrior passed = f.Prior(55.0);  // two passes.
  const FramePrior held = f.Prior(40.0);    // one.
  const Estimate two = f.Run(options, &passed);
  ExpectSameCandidates(f.Run(options, &held), two);
  EXPECT_EQ(two.Humanoids().size(), 1u);
}

// Where the humanoid passes the full threshold, the lower one searches nothing further: the same
// candidates as without hysteresis.
TEST(TrackedThresholdTest, AHumanoidThatPassesIsSearchedAsWithout) {
  Fixture f;
  f.spec.humanoid_pose = Pose2D{1.6, 0.1, DegToRad(120.0)};
  f.frame = *SimulateFrame(f.spec);
  const EstimatorOptions options = f.Options();
  EstimatorOptions off = options;
  off.tracked_score_threshold = options.score_threshold;
  const FramePrior prior = f.Prior(55.0);
  const Estimate held = f.Run(options, &prior);
  ExpectSameCandidates(held, f.Run(off, &prior));
  ASSERT_EQ(held.Humanoids().size(), 1u);
  EXPECT_TRUE(f.NearTruth(held.Humanoids().front()));
  EXPECT_EQ(held.Humanoids().front().score_threshold, options.score_threshold);
}

// An initial pose (PoseTracker::SetInitialPose) stands in for the frame before until the robot
// is first found, and again after Reset: a robot too far to be found cold is found from the
// first frame.
TEST(TrackedThresholdTest, AnInitialPoseFindsAFarRobotFromTheFirstFrame) {
  const Fixture f;
  const auto estimator = std::move(Estimator::Create(f.Options(), f.templates).value());
  PoseTracker cold(estimator.get());
  EXPECT_TRUE(cold.EstimateDepth(f.frame.depth, f.spec.intrinsics)->Humanoids().empty());

  PoseTracker tracker(estimator.get());
  tracker.SetInitialPose(f.Prior(0.0).pose);
  const Estimate first = *tracker.EstimateDepth(f.frame.depth, f.spec.intrinsics);
  ASSERT_EQ(first.Humanoids().size(), 1u);
  EXPECT_TRUE(f.NearTruth(first.Humanoids().front()));
  EXPECT_TRUE(first.tracking.prior_given);
  EXPECT_EQ(first.tracking.prior_template, "");  // an initial pose, not a frame's.
  EXPECT_TRUE(tracker.prior().has_value());

  // Once found it is followed from frame to frame; a frame without it drops the pose, and the
  // initial pose does not come back.
  ASSERT_EQ(tracker.EstimateDepth(f.frame.depth, f.spec.intrinsics)->Humanoids().size(), 1u);
  FrameSpec empty = f.spec;
  empty.humanoid_pose = Pose2D{30.0, 0.0, 0.0};  // out of range: floor and clutter only.
  const SimulatedFrame nothing = *SimulateFrame(empty);
  EXPECT_TRUE(tracker.EstimateDepth(nothing.depth, f.spec.intrinsics)->Humanoids().empty());
  EXPECT_TRUE(tracker.EstimateDepth(f.frame.depth, f.spec.intrinsics)->Humanoids().empty());
  // A restarted stream starts from the initial pose again.
  tracker.Reset();
  EXPECT_EQ(tracker.EstimateDepth(f.frame.depth, f.spec.intrinsics)->Humanoids().size(), 1u);
}

TEST(TrackedThresholdTest, OutOfRangeIsRefused) {
  const Fixture f;
  EstimatorOptions o = f.Options();
  o.tracked_score_threshold = -1.0;
  EXPECT_FALSE(Estimator::Create(o, f.templates).ok());
  o.tracked_score_threshold = 101.0;
  EXPECT_FALSE(Estimator::Create(o, f.templates).ok());
  o.tracked_score_threshold = std::nan("");
  EXPECT_FALSE(Estimator::Create(o, f.templates).ok());
}

}  // namespace
}  // namespace hpose
