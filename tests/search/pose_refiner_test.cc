// The continuous refinement of a lattice pose: it converges to the truth from a perturbed start,
// never leaves its basin, and its evidence tells the true pose from the flipped one. Frames come
// from the simulator with the Kinect v1 noise model (or without it, where exactness is asked).
#include "core/search/pose_refiner.h"

#include <gtest/gtest.h>

#include <cmath>

#include <Eigen/Eigenvalues>

#include "core/depth/cluster_extractor.h"
#include "core/depth/depth_to_cloud.h"
#include "core/depth/range_image.h"
#include "core/search/estimator.h"
#include "core/search/surface_model.h"
#include "core/sim/frame_simulator.h"
#include "core/sim/humanoid_model.h"

namespace hpose {
namespace {

VoxelTemplate ModelTemplate(const std::string& preset) {
  const HumanoidModel model = *HumanoidModel::FromPreset(preset);
  return *MakeTemplateFromPoints(*model.SampleSurface(0.004), preset, 0.016, preset, "test");
}

// One simulated frame, cut into what the refinement reads: the humanoid's cluster points, the
// range image of the whole frame and the true sensor mount.
struct Scene {
  Pose2D truth;
  PointCloud cloud;
  std::vector<Cluster> clusters;
  Cluster humanoid;
  RangeImage range;
  Eigen::Isometry3d sensor_from_ground;

  Observation Obs() const { return Observation{&humanoid.points, &range, sensor_from_ground}; }
};

Scene MakeScene(const Pose2D& truth, bool noise, std::uint64_t seed = 7) {
  FrameSpec spec;
  spec.humanoid_pose = truth;
  spec.noise = noise;
  spec.seed = seed;
  const SimulatedFrame frame = *SimulateFrame(spec);
  Scene s;
  s.truth = truth;
  s.cloud = *DepthToCloud(frame.depth, spec.intrinsics, {});
  s.clusters = *ExtractClusters(s.cloud, frame.sensor_mount, {});
  double best = 1e9;
  for (const Cluster& c : s.clusters) {
    const double d = std::hypot(c.centroid.x() - truth.x, c.centroid.y() - truth.y);
    if (d < best) {
      best = d;
      s.humanoid = c;
    }
  }
  s.range = RangeImage::FromCloud(s.cloud);
  s.sensor_from_ground = frame.sensor_mount.ground_from_sensor.inverse();
  return s;
}

double PositionError(const Pose2D& a, const Pose2D& b) { return std::hypot(a.x - b.x, a.y - b.y); }
double ThetaErrorDeg(const Pose2D& a, const Pose2D& b) {
  return std::abs(RadToDeg(AngleDiff(a.theta, b.theta)));
}

TEST(PoseRefinerTest, ConvergesToTheTruthFromAPerturbedStartUnderNoise) {
  const SurfaceModel model(ModelTemplate("standing"));
  for (const double theta_deg : {0.0, 30.0, 135.0, -100.0}) {
    const Pose2D truth{1.5, 0.05, DegToRad(theta_deg)};
    const Scene s = MakeScene(truth, /*noise=*/true);
    ASSERT_GT(s.humanoid.points.size(), 300u);
    const Pose2D start{truth.x + 0.012, truth.y - 0.010, truth.theta + DegToRad(3.0)};
    const RefinedPose r = RefinePose(model, s.Obs(), start);
    EXPECT_LT(PositionError(r.pose, truth), 0.004) << "theta " << theta_deg;
    EXPECT_LT(ThetaErrorDeg(r.pose, truth), 1.0) << "theta " << theta_deg;
    EXPECT_FALSE(r.at_basin_limit);
    EXPECT_GT(r.evidence.Explained(), 0.8);
  }
}

TEST(PoseRefinerTest, IsExactWithoutNoise) {
  const SurfaceModel model(ModelTemplate("standing"));
  const Pose2D truth{2.0, -0.2, DegToRad(60.0)};
  const Scene s = MakeScene(truth, /*noise=*/false);
  const Pose2D start{truth.x - 0.010, truth.y + 0.008, truth.theta - DegToRad(2.0)};
  const RefinedPose r = RefinePose(model, s.Obs(), start);
  EXPECT_LT(PositionError(r.pose, truth), 0.001);
  EXPECT_LT(ThetaErrorDeg(r.pose, truth), 0.2);
  EXPECT_TRUE(r.converged);
}

TEST(PoseRefinerTest, NeverLeavesTheBasinOfItsStart) {
  const SurfaceModel model(ModelTemplate("standing"));
  const Pose2D truth{1.2, 0.0, 0.0};
  const Scene s = MakeScene(truth, /*noise=*/true);
  RefineOptions options;
  const Pose2D start{truth.x + 0.06, truth.y, truth.theta + DegToRad(12.0)};
  const RefinedPose r = RefinePose(model, s.Obs(), start, options);
  EXPECT_LE(PositionError(r.pose, start), options.max_shift_m + 1e-9);
  EXPECT_LE(ThetaErrorDeg(r.pose, start), RadToDeg(options.max_turn_rad) + 1e-6);
  EXPECT_TRUE(r.at_basin_limit);
  // It still moved toward the truth.
  EXPECT_LT(PositionError(r.pose, truth), PositionError(start, truth));
}

TEST(PoseRefinerTest, DisabledKeepsTheStartAndReportsItsEvidence) {
  const SurfaceModel model(ModelTemplate("standing"));
  const Pose2D truth{1.2, 0.0, 0.0};
  const Scene s = MakeScene(truth, /*noise=*/true);
  RefineOptions options;
  options.enabled = false;
  const Pose2D start{truth.x + 0.01, truth.y, truth.theta};
  const RefinedPose r = RefinePose(model, s.Obs(), start, options);
  EXPECT_EQ(r.pose.x, start.x);
  EXPECT_EQ(r.pose.theta, start.theta);
  EXPECT_EQ(r.iterations, 0);
  EXPECT_GT(r.evidence.data_points, 0);
}

TEST(PoseRefinerTest, EvidenceTellsTheTruthFromTheFlippedPose) {
  // Our model carries a battery pack on its back: front and back differ.
  const SurfaceModel model(ModelTemplate("standing"));
  for (const double theta_deg : {0.0, 180.0, 90.0}) {
    const Pose2D truth{1.2, 0.0, DegToRad(theta_deg)};
    const Scene s = MakeScene(truth, /*noise=*/true);
    const RefinedPose right = RefinePose(model, s.Obs(), truth);
    const RefinedPose flipped =
        RefinePose(model, s.Obs(), Pose2D{truth.x, truth.y, NormalizeAngle(truth.theta + kPi)});
    EXPECT_GT(right.evidence.Fit(), flipped.evidence.Fit()) << "theta " << theta_deg;
    EXPECT_LT(right.evidence.cost, flipped.evidence.cost) << "theta " << theta_deg;
  }
}

TEST(PoseRefinerTest, SeenThroughTemplateIsContradicted) {
  // A template placed beside the humanoid, where the sensor sees the floor behind: most of its
  // visible surface is contradicted, and it explains little of the cluster.
  const SurfaceModel model(ModelTemplate("standing"));
  const Pose2D truth{1.5, 0.0, 0.0};
  const Scene s = MakeScene(truth, /*noise=*/true);
  const PoseEvidence there = EvaluatePose(model, s.Obs(), truth);
  const PoseEvidence beside = EvaluatePose(model, s.Obs(), Pose2D{1.5, 0.35, 0.0});
  EXPECT_LT(there.Contradicted(), 0.1);
  EXPECT_GT(beside.Contradicted(), 0.5);
  EXPECT_GT(there.Explained(), 0.8);
  EXPECT_LT(beside.Explained(), 0.2);
}

TEST(PoseRefinerTest, CovarianceIsPositiveAndGrowsWithDistance) {
  const SurfaceModel model(ModelTemplate("standing"));
  double var_near = 0.0, var_far = 0.0;
  for (const double d : {1.0, 3.0}) {
    const Pose2D truth{d, 0.0, DegToRad(20.0)};
    const Scene s = MakeScene(truth, /*noise=*/true);
    const RefinedPose r = RefinePose(model, s.Obs(), truth);
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(r.covariance);
    EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0) << "distance " << d;
    (d < 2.0 ? var_near : var_far) = r.covariance(0, 0);
  }
  EXPECT_GT(var_far, var_near);
}

TEST(PoseRefinerTest, EstimatorReportsRefinedAndLatticePoses) {
  EstimatorOptions options = DefaultEstimatorOptions();
  auto refined = std::move(Estimator::Create(options, {ModelTemplate("standing")}).value());
  options.refine.enabled = false;
  auto lattice = std::move(Estimator::Create(options, {ModelTemplate("standing")}).value());
  FrameSpec spec;
  spec.humanoid_pose = Pose2D{1.6, 0.1, DegToRad(45.0)};
  spec.seed = 3;
  spec.clutter = 2;
  const SimulatedFrame frame = *SimulateFrame(spec);
  const Estimate with = *refined->EstimateDepth(frame.depth, spec.intrinsics);
  const Estimate without = *lattice->EstimateDepth(frame.depth, spec.intrinsics);
  const std::vector<Detection> with_humanoids = with.Humanoids();
  const std::vector<Detection> without_humanoids = without.Humanoids();
  ASSERT_FALSE(with_humanoids.empty());
  ASSERT_FALSE(without_humanoids.empty());
  const Candidate& r = with_humanoids.front().best;
  const Candidate& l = without_humanoids.front().best;
  EXPECT_TRUE(r.refined);
  EXPECT_FALSE(l.refined);
  EXPECT_EQ(l.pose.x, l.lattice_pose.x);
  // The refined pose is nearer the truth than the lattice pose it started from, and within its
  // basin.
  EXPECT_LE(PositionError(r.pose, spec.humanoid_pose),
            PositionError(r.lattice_pose, spec.humanoid_pose) + 1e-9);
  EXPECT_LT(PositionError(r.pose, spec.humanoid_pose), 0.005);
  EXPECT_LT(ThetaErrorDeg(r.pose, spec.humanoid_pose), 1.5);
  EXPECT_LE(PositionError(r.pose, r.lattice_pose), options.refine.max_shift_m + 1e-9);
  EXPECT_GT(r.covariance(0, 0), 0.0);
  EXPECT_GT(r.fit.fit, 50.0);
  EXPECT_FALSE(r.heading_ambiguous);
  EXPECT_GE(with.timings.refine_ms, 0.0);
  EXPECT_LE(with.timings.refine_ms, with.timings.search_ms);
}

}  // namespace
}  // namespace hpose
