// A tracked frame's check that a refined pose keeps the previous frame's heading
// (ConfirmsPreviousHeading, EstimatorOptions::tracked_heading_confirm_rad), which spares the
// runner-up heading's search: the robot's own pose confirms it, the pose turned about never does
// (a robot turned about between two frames whose optimum still faces its old way), and tracked
// frames give the same poses with the check as without it.
#include "core/search/heading_confirmation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/depth/cluster_extractor.h"
#include "core/depth/depth_to_cloud.h"
#include "core/depth/range_image.h"
#include "core/search/estimator.h"
#include "core/search/fit_summary.h"
#include "core/sim/frame_simulator.h"
#include "tests/search/model_templates.h"

namespace hpose {
namespace {

using testing::ModelTemplate;

Pose2D TurnedAbout(const Pose2D& p) { return Pose2D{p.x, p.y, NormalizeAngle(p.theta + kPi)}; }

// What the refinement reads of one simulated frame: the cluster nearest the robot, the range
// image and the true sensor mount.
struct Frame {
  std::vector<Cluster> clusters;
  const Cluster* robot = nullptr;
  RangeImage range;
  Eigen::Isometry3d sensor_from_ground;
  Observation Obs() const { return Observation{&robot->points, &range, sensor_from_ground}; }
};

Frame Simulate(const FrameSpec& spec) {
  const SimulatedFrame sim = *SimulateFrame(spec);
  const PointCloud cloud = *DepthToCloud(sim.depth, spec.intrinsics, {});
  Frame f;
  f.clusters = *ExtractClusters(cloud, sim.sensor_mount, {});
  f.range = RangeImage::FromCloud(cloud);
  f.sensor_from_ground = sim.sensor_mount.ground_from_sensor.inverse();
  double nearest = 1e9;
  for (const Cluster& c : f.clusters) {
    const double d =
        std::hypot(c.centroid.x() - spec.humanoid_pose.x, c.centroid.y() - spec.humanoid_pose.y);
    if (d < nearest) {
      nearest = d;
      f.robot = &c;
    }
  }
  return f;
}

TEST(HeadingConfirmationTest, TheRobotsPoseConfirmsItsHeadingAndThePoseTurnedAboutNever) {
  const SurfaceModel model(ModelTemplate("standing"));
  const EstimatorOptions defaults = DefaultEstimatorOptions();
  const RefineOptions& refine = defaults.refine;
  const HeadingConfirmOptions options{defaults.tracked_heading_confirm_rad,
                                      defaults.min_humanoid_fit,
                                      defaults.heading_views.max_fit_sigmas};
  ASSERT_GT(options.within_rad, DegToRad(5.0));
  int frames = 0, confirmed = 0;
  for (const double distance : {1.3, 2.2, 3.2}) {
    for (const double theta_deg : {-90.0, 0.0, 150.0}) {
      for (std::uint64_t seed = 1; seed <= 2; ++seed) {
        FrameSpec spec;
        spec.humanoid_pose = Pose2D{distance, 0.1, DegToRad(theta_deg)};
        spec.clutter = 2;
        spec.seed = seed;
        const Frame f = Simulate(spec);
        ASSERT_NE(f.robot, nullptr);
        const std::string where = "distance " + std::to_string(distance) + " theta " +
                                  std::to_string(theta_deg) + " seed " + std::to_string(seed);
        const Pose2D truth = spec.humanoid_pose;
        const RefinedPose right = RefinePose(model, f.Obs(), truth, refine);
        const FitSummary right_fit = Summarise(right.evidence);
        // The previous frame a few degrees behind (the robot turns): its heading confirmed where
        // the turned-about pose fits far worse.
        const double previous = truth.theta - DegToRad(5.0);
        const bool ok = ConfirmsPreviousHeading(model, f.Obs(), truth, right.pose, right_fit,
                                                previous, options, refine);
        ++frames;
        confirmed += ok ? 1 : 0;
        // Near and seen from the front or the back, the turned-about pose is far behind.
        if (distance < 3.0 && theta_deg != -90.0) EXPECT_TRUE(ok) << where;
        if (ok) {
          const FitSummary turned_fit =
              Summarise(EvaluatePose(model, f.Obs(), TurnedAbout(right.pose), refine));
          EXPECT_GT(
              right_fit.fit - turned_fit.fit,
              options.far_behind_sigmas * std::hypot(right_fit.fit_sigma, turned_fit.fit_sigma))
              << where;
        }
        // The robot turned about since the previous frame, the optimum still facing the old way:
        // the turned-about pose is the robot's and fits as well or better, never far behind.
        const RefinedPose wrong = RefinePose(model, f.Obs(), TurnedAbout(truth), refine);
        EXPECT_FALSE(ConfirmsPreviousHeading(model, f.Obs(), TurnedAbout(truth), wrong.pose,
                                             Summarise(wrong.evidence), TurnedAbout(truth).theta,
                                             options, refine))
            << where;
        // Nothing is confirmed beyond the angle, below the fit, or with the check off.
        EXPECT_FALSE(ConfirmsPreviousHeading(model, f.Obs(), truth, right.pose, right_fit,
                                             truth.theta + options.within_rad + DegToRad(3.0),
                                             options, refine))
            << where;
        // A pose the refinement left on its basin's bound, a full turn or shift from its start:
        // another start may fit better.
        const Pose2D turned_start{right.pose.x, right.pose.y,
                                  NormalizeAngle(right.pose.theta - refine.max_turn_rad)};
        const Pose2D shifted_start{right.pose.x - refine.max_shift_m, right.pose.y,
                                   right.pose.theta};
        for (const Pose2D& start : {turned_start, shifted_start}) {
          EXPECT_FALSE(ConfirmsPreviousHeading(model, f.Obs(), start, right.pose, right_fit,
                                               previous, options, refine))
              << where;
        }
        HeadingConfirmOptions strict = options;
        strict.min_fit = right_fit.fit + 0.1;
        EXPECT_FALSE(ConfirmsPreviousHeading(model, f.Obs(), truth, right.pose, right_fit, previous,
                                             strict, refine))
            << where;
        HeadingConfirmOptions no_angle = options, no_margin = options;
        no_angle.within_rad = 0.0;
        no_margin.far_behind_sigmas = 0.0;
        for (const HeadingConfirmOptions& off : {no_angle, no_margin}) {
          EXPECT_FALSE(ConfirmsPreviousHeading(model, f.Obs(), truth, right.pose, right_fit,
                                               previous, off, refine))
              << where;
        }
      }
    }
  }
  std::printf("the robot's pose confirmed its heading in %d of %d frames\n", confirmed, frames);
  // Side on, or at 3.2 m where front and back fit almost alike, the turned-about pose may come
  // within the margin: the runner-up is searched there.
  EXPECT_GE(confirmed, 8);
}

// A previous frame's "standing" humanoid at `pose`.
FramePrior PriorAt(const Pose2D& pose) {
  FramePrior prior;
  prior.has_pose = true;
  prior.template_name = "standing";
  prior.pose = pose;
  return prior;
}

bool SamePose(const Pose2D& a, const Pose2D& b) {
  return a.x == b.x && a.y == b.y && a.theta == b.theta;
}

// Tracked frames, the previous heading a few degrees behind the robot's or turned about: the
// same humanoid, template and pose with the check as without it; a candidate that confirmed its
// heading has no runner-up and faces the previous frame's way; with the previous heading turned
// about nothing is confirmed and every candidate is the same, runner-up included.
TEST(HeadingConfirmationTest, TrackedFramesGiveTheSamePosesWithItAsWithout) {
  const std::vector<VoxelTemplate> templates = {ModelTemplate("standing"),
                                                ModelTemplate("right_arm_raised")};
  EstimatorOptions with = DefaultEstimatorOptions();
  EstimatorOptions without = with;
  without.tracked_heading_confirm_rad = 0.0;
  const auto confirming = std::move(Estimator::Create(with, templates).value());
  const auto searching = std::move(Estimator::Create(without, templates).value());
  int confirmed = 0;
  for (const double distance : {1.4, 2.2, 3.0}) {
    for (const double theta_deg : {-90.0, 0.0, 150.0}) {
      for (std::uint64_t seed = 1; seed <= 2; ++seed) {
        FrameSpec spec;
        spec.humanoid_pose = Pose2D{distance, 0.1, DegToRad(theta_deg)};
        spec.clutter = 3;
        spec.seed = seed;
        const SimulatedFrame frame = *SimulateFrame(spec);
        for (const double offset_deg : {-4.0, 180.0}) {
          const Pose2D previous{spec.humanoid_pose.x - 0.02, spec.humanoid_pose.y,
                                NormalizeAngle(spec.humanoid_pose.theta + DegToRad(offset_deg))};
          const FramePrior prior = PriorAt(previous);
          const Estimate a = *confirming->EstimateDepth(frame.depth, spec.intrinsics, &prior);
          const Estimate b = *searching->EstimateDepth(frame.depth, spec.intrinsics, &prior);
          const std::string where = "distance " + std::to_string(distance) + " theta " +
                                    std::to_string(theta_deg) + " seed " + std::to_string(seed) +
                                    " previous heading offset " + std::to_string(offset_deg);
          ASSERT_EQ(a.Humanoids().size(), b.Humanoids().size()) << where;
          ASSERT_FALSE(a.Humanoids().empty()) << where;
          const Candidate& ha = a.Humanoids().front().best;
          const Candidate& hb = b.Humanoids().front().best;
          EXPECT_EQ(ha.template_name, hb.template_name) << where;
          EXPECT_TRUE(SamePose(ha.pose, hb.pose)) << where;
          EXPECT_LT(std::abs(RadToDeg(AngleDiff(ha.pose.theta, spec.humanoid_pose.theta))), 10.0)
              << where;
          ASSERT_EQ(a.candidates.size(), b.candidates.size()) << where;
          for (size_t i = 0; i < a.candidates.size(); ++i) {
            const Candidate& ca = a.candidates[i];
            const Candidate& cb = b.candidates[i];
            EXPECT_FALSE(cb.heading_confirmed) << where;
            EXPECT_TRUE(SamePose(ca.pose, cb.pose)) << where << " candidate " << i;
            if (ca.heading_confirmed) {
              ++confirmed;
              EXPECT_NE(offset_deg, 180.0) << where;
              EXPECT_FALSE(ca.has_runner_up) << where;
              EXPECT_LE(std::abs(AngleDiff(ca.pose.theta, previous.theta)),
                        with.tracked_heading_confirm_rad)
                  << where;
            } else {
              EXPECT_EQ(ca.has_runner_up, cb.has_runner_up) << where << " candidate " << i;
              EXPECT_EQ(ca.runner_up_score, cb.runner_up_score) << where << " candidate " << i;
              EXPECT_TRUE(SamePose(ca.runner_up_pose, cb.runner_up_pose)) << where;
            }
          }
        }
      }
    }
  }
  std::printf("candidates that confirmed the previous heading: %d\n", confirmed);
  EXPECT_GE(confirmed, 6);
}

}  // namespace
}  // namespace hpose
