// The estimator's pre-filters skip only what cannot match: a robot whose top the image border
// cuts off is still searched with the template it shows part of. Its fit gate refuses clutter,
// and spares the depth images' heading choice where neither heading could pass it; its evidence
// gate refuses clutter that covers little of the template.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/depth/depth_to_cloud.h"
#include "core/depth/floor_estimate.h"
#include "core/search/detection_order.h"
#include "core/search/estimator.h"
#include "core/search/pose_tracker.h"
#include "core/sim/depth_renderer.h"
#include "core/sim/frame_simulator.h"
#include "core/sim/primitive.h"
#include "core/sim/scene.h"
#include "tests/search/model_templates.h"

namespace hpose {
namespace {

using testing::ModelTemplate;

// frame_bench's frame 23: a Nao 3.5 m away, which scores less than a box 2 m away.
FrameSpec FarNaoBehindClutter() {
  FrameSpec spec;
  spec.preset = "right_arm_raised";
  spec.humanoid_pose = Pose2D{3.5, -0.05, DegToRad(151.0)};
  spec.clutter = 4;
  spec.seed = 24;
  return spec;
}

int CandidatesOf(const Estimate& e, const std::string& name) {
  int n = 0;
  for (const Candidate& c : e.candidates) n += c.template_name == name;
  return n;
}

// A sensor 0.34 m high looking 15 degrees down: at 1 m it sees up to about 0.45 m, so the Nao's
// raised arm (top at 0.64 m) and its head are cut off.
FrameSpec NaoCutByTheImageTop() {
  FrameSpec spec;
  spec.preset = "right_arm_raised";
  spec.humanoid_pose = Pose2D{1.0, 0.0, DegToRad(150.0)};
  spec.sensor_pitch_rad = DegToRad(15.0);
  spec.seed = 11;
  return spec;
}

TEST(EstimatorGatesTest, RobotCutByTheImageTopIsStillSearchedWithItsTemplate) {
  const FrameSpec spec = NaoCutByTheImageTop();
  const SimulatedFrame frame = *SimulateFrame(spec);
  EstimatorOptions options = DefaultEstimatorOptions();
  options.score_threshold = 0.0;
  const std::vector<VoxelTemplate> templates = {ModelTemplate("standing"),
                                                ModelTemplate("right_arm_raised")};
  options.height_check_uses_view = false;  // the previous behaviour: the template's full height.
  const Estimate before =
      *Estimator::Create(options, templates).value()->EstimateDepth(frame.depth, spec.intrinsics);
  options.height_check_uses_view = true;
  const Estimate now =
      *Estimator::Create(options, templates).value()->EstimateDepth(frame.depth, spec.intrinsics);
  EXPECT_EQ(CandidatesOf(before, "right_arm_raised"), 0);
  ASSERT_EQ(CandidatesOf(now, "right_arm_raised"), 1);
  for (const Candidate& c : now.candidates) {
    if (c.template_name != "right_arm_raised") continue;
    EXPECT_LT(std::hypot(c.pose.x - 1.0, c.pose.y), 0.01);
    EXPECT_LT(std::abs(RadToDeg(AngleDiff(c.pose.theta, spec.humanoid_pose.theta))), 3.0);
  }
}

// A fit says how much of its template the view holds: the robot above, its head and raised
// arm above the image's top, shows part of it; seen from a level sensor, all of it.
TEST(EstimatorGatesTest, AFitSaysHowMuchOfItsTemplateIsInView) {
  const std::vector<VoxelTemplate> templates = {ModelTemplate("right_arm_raised")};
  FrameSpec spec = NaoCutByTheImageTop();
  std::vector<double> in_view;
  for (const double pitch_deg : {15.0, 0.0}) {
    spec.sensor_pitch_rad = DegToRad(pitch_deg);
    const SimulatedFrame frame = *SimulateFrame(spec);
    const Estimate e = *Estimator::Create(DefaultEstimatorOptions(), templates)
                            .value()
                            ->EstimateDepth(frame.depth, spec.intrinsics);
    const std::vector<Detection> humans = e.Humanoids();
    ASSERT_EQ(humans.size(), 1u) << pitch_deg;
    const Candidate& c = humans.front().best;
    ASSERT_TRUE(c.refined);
    EXPECT_LT(std::hypot(c.pose.x - 1.0, c.pose.y), 0.01) << pitch_deg;
    in_view.push_back(c.fit.in_view);
  }
  EXPECT_GT(in_view[0], 0.3);
  EXPECT_LT(in_view[0], 0.9);
  EXPECT_GT(in_view[1], 0.97);
  EXPECT_LE(in_view[1], 1.0);
}

// Where nothing above an object returned a reading (open space, beyond the sensor's range) the
// cloud's points end at the object's top, but the depth image's intrinsics say where the view
// ends: a post 0.36 m high, 2.5 m ahead of a level sensor 0.34 m up that sees to 1.3 m there, is
// too short for the 0.59 m template and is not searched; given as a cloud alone, it is. The same
// post half out of the image at its left edge is searched: the image's side cuts it, and what
// shows of a robot there (an arm, a shoulder) need not reach its top.
TEST(EstimatorGatesTest, TheImagesTopNotTheHighestPointSeenEndsTheView) {
  const Intrinsics intrinsics = Intrinsics::KinectV1(640, 480);
  Scene scene;
  Eigen::Isometry3d at = Eigen::Isometry3d::Identity();
  at.translation() = Eigen::Vector3d(2.5, 0.1, 0.18);
  ASSERT_TRUE(scene.AddClutter(Primitive::Cylinder("post", 0.05, 0.36, at)).ok());
  const double edge_y = 2.5 * intrinsics.cx / intrinsics.fx;  // the left edge's ray at x 2.5 m.
  at.translation() = Eigen::Vector3d(2.5, edge_y, 0.18);
  ASSERT_TRUE(scene.AddClutter(Primitive::Cylinder("cut", 0.05, 0.36, at)).ok());
  const DepthImage depth =
      DepthRenderer::Create(intrinsics, FloorEstimate::FromHeightPitchRoll(0.34, 0.0, 0.0))
          ->Render(scene);
  const std::unique_ptr<Estimator> estimator =
      Estimator::Create(DefaultEstimatorOptions(), {ModelTemplate("standing")}).value();
  const auto near = [](const Estimate& e, double y) -> const ClusterSummary* {
    for (const ClusterSummary& c : e.clusters) {
      if (std::hypot(c.centroid.x() - 2.5, c.centroid.y() - y) < 0.1) return &c;
    }
    return nullptr;
  };
  const auto post = [&](const Estimate& e) { return near(e, 0.1); };
  const Estimate from_image = *estimator->EstimateDepth(depth, intrinsics);
  ASSERT_NE(post(from_image), nullptr);
  EXPECT_NEAR(post(from_image)->max.z(), 0.36, 0.02);
  EXPECT_FALSE(post(from_image)->searched);
  const ClusterSummary* cut = near(from_image, edge_y - 0.02);
  ASSERT_NE(cut, nullptr);
  EXPECT_NEAR(cut->max.z(), 0.36, 0.02);
  EXPECT_TRUE(cut->searched);
  for (const Candidate& c : from_image.candidates) EXPECT_EQ(c.cluster_index, cut->index);

  const Result<PointCloud> cloud = DepthToCloud(depth, intrinsics);
  ASSERT_TRUE(cloud.ok());
  const Estimate from_cloud = *estimator->EstimateCloud(*cloud);
  ASSERT_NE(post(from_cloud), nullptr);
  EXPECT_TRUE(post(from_cloud)->searched);
}

// A level sensor in an open room (nothing beyond the objects within range) sees nothing above
// its tallest object. A box a little shorter than the template, the only object: the
// template placed on it reaches above the box's top, where the depth image looked and got no
// return. The range image spans the image's view (range_image_spans_view), so that part is
// seen through and counts against the fit; spanning the readings alone, it was out of view,
// neither confirmed nor contradicted, and the fit rested on the part the box matched.
TEST(EstimatorGatesTest, NoReturnAboveTheTallestObjectCountsAgainstTheFit) {
  const Intrinsics intrinsics = Intrinsics::KinectV1(640, 480);
  Scene scene;
  Eigen::Isometry3d at = Eigen::Isometry3d::Identity();
  at.translation() = Eigen::Vector3d(1.6, 0.1, 0.25);
  ASSERT_TRUE(scene.AddClutter(Primitive::Box("box", Eigen::Vector3d(0.16, 0.22, 0.5), at)).ok());
  const DepthImage depth =
      DepthRenderer::Create(intrinsics, FloorEstimate::FromHeightPitchRoll(0.34, 0.0, 0.0))
          ->Render(scene);
  EstimatorOptions options = DefaultEstimatorOptions();
  options.score_threshold = 0.0;  // refine the box's candidate whatever it scores.
  std::vector<FitSummary> fits;
  for (const bool spans_view : {false, true}) {
    options.range_image_spans_view = spans_view;
    const Estimate e = *Estimator::Create(options, {ModelTemplate("standing")})
                            .value()
                            ->EstimateDepth(depth, intrinsics);
    ASSERT_EQ(e.candidates.size(), 1u) << spans_view;
    ASSERT_TRUE(e.candidates[0].refined) << spans_view;
    fits.push_back(e.candidates[0].fit);
  }
  EXPECT_LT(fits[0].in_view, 0.95);
  EXPECT_GT(fits[1].in_view, 0.99);
  EXPECT_GT(fits[1].contradicted, fits[0].contradicted + 0.03);
  EXPECT_LT(fits[1].fit, fits[0].fit - 3.0);
  // A cloud alone has no edges: its readings' extent stands for the view, as before.
  const Result<PointCloud> cloud = DepthToCloud(depth, intrinsics);
  ASSERT_TRUE(cloud.ok());
  const Estimate from_cloud =
      *Estimator::Create(options, {ModelTemplate("standing")}).value()->EstimateCloud(*cloud);
  ASSERT_EQ(from_cloud.candidates.size(), 1u);
  EXPECT_LT(from_cloud.candidates[0].fit.in_view, 0.95);
}

// A depth image registered to colour has a border without readings where the two views do not
// overlap (PCL's recorded Kinect frames: the top 15 of 480 rows). The robot whose head and
// raised arm reach the image's top (as above) is seen through the blank rows' band only with
// no band left to the readings (range_image_edge_band 0): its fit rests on the rows that can
// have a reading, as where the image's top cuts it, with the band by default.
TEST(EstimatorGatesTest, ABlankBandAtTheImagesTopDoesNotContradictARobot) {
  const FrameSpec spec = NaoCutByTheImageTop();
  SimulatedFrame frame = *SimulateFrame(spec);
  int blanked = 0;
  for (int v = 0; v < 15; ++v) {
    for (int u = 0; u < frame.depth.width; ++u) {
      blanked += frame.depth.at(u, v) != 0;
      frame.depth.at(u, v) = 0;
    }
  }
  ASSERT_GT(blanked, 100);  // the robot reached those rows.
  EstimatorOptions options = DefaultEstimatorOptions();
  std::vector<FitSummary> fits;
  for (const double band : {0.0, options.range_image_edge_band}) {
    options.range_image_edge_band = band;
    const Estimate e = *Estimator::Create(options, {ModelTemplate("right_arm_raised")})
                            .value()
                            ->EstimateDepth(frame.depth, spec.intrinsics);
    ASSERT_EQ(e.Humanoids().size(), 1u) << band;
    ASSERT_TRUE(e.candidates[0].refined) << band;
    fits.push_back(e.candidates[0].fit);
  }
  EXPECT_GT(fits[0].in_view, fits[1].in_view + 0.03);
  EXPECT_GT(fits[0].contradicted, fits[1].contradicted + 0.03);
  EXPECT_GT(fits[1].fit, fits[0].fit + 3.0);
  options.range_image_edge_band = 0.5;
  EXPECT_FALSE(Estimator::Create(options, {ModelTemplate("right_arm_raised")}).ok());
  options.range_image_edge_band = std::nan("");
  EXPECT_FALSE(Estimator::Create(options, {ModelTemplate("right_arm_raised")}).ok());
}

TEST(EstimatorGatesTest, AClusterTooLargeForATemplateIsSkippedByABound) {
  // A template can cover at most as many cluster voxels as it has voxels: a tiny template
  // cannot reach the threshold on a humanoid-sized cluster, so it is not searched.
  FrameSpec spec;
  spec.seed = 12;
  const SimulatedFrame frame = *SimulateFrame(spec);
  std::vector<Eigen::Vector3f> pts;
  for (int i = 0; i < 40; ++i) pts.emplace_back(0.0f, 0.0f, 0.01f + 0.012f * i);  // a thin pole.
  EstimatorOptions options = DefaultEstimatorOptions();
  options.max_height_ratio_error = -1.0;
  const Estimate e = *Estimator::Create(options, {*MakeTemplateFromPoints(pts, "pole", 0.016),
                                                  ModelTemplate("standing")})
                          .value()
                          ->EstimateDepth(frame.depth, spec.intrinsics);
  EXPECT_EQ(CandidatesOf(e, "pole"), 0);
  EXPECT_EQ(CandidatesOf(e, "standing"), 1);
}

// Clutter that reaches the score threshold is no humanoid when its refined pose leaves much of
// the template's visible surface seen through (min_humanoid_fit); the humanoid itself fits well
// and stays one. A lowered score threshold lets clutter of a humanoid's height through on these
// frames, as the default one does on a few.
TEST(EstimatorGatesTest, ClutterThatFitsPoorlyIsNoHumanoid) {
  const std::vector<VoxelTemplate> templates = {ModelTemplate("standing"),
                                                ModelTemplate("right_arm_raised")};
  EstimatorOptions gated = DefaultEstimatorOptions();
  gated.score_threshold = 40.0;
  EstimatorOptions score_only = gated;
  score_only.min_humanoid_fit = 0.0;
  score_only.min_humanoid_evidence = 0.0;  // the score alone.
  const auto with_fit = std::move(Estimator::Create(gated, templates).value());
  const auto without = std::move(Estimator::Create(score_only, templates).value());
  std::vector<FrameSpec> specs;
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    FrameSpec spec;
    spec.humanoid_pose = Pose2D{1.3, -0.1, DegToRad(40.0 * static_cast<double>(seed))};
    spec.clutter = 4;
    spec.seed = seed;
    specs.push_back(spec);
  }
  specs.push_back(FarNaoBehindClutter());
  int clutter_by_score = 0, outscored = 0;
  for (size_t seed = 0; seed < specs.size(); ++seed) {
    const FrameSpec& spec = specs[seed];
    const SimulatedFrame frame = *SimulateFrame(spec);
    const Estimate a = *with_fit->EstimateDepth(frame.depth, spec.intrinsics);
    const Estimate b = *without->EstimateDepth(frame.depth, spec.intrinsics);
    const auto near_truth = [&](const Detection& d) {
      return std::hypot(d.best.pose.x - spec.humanoid_pose.x,
                        d.best.pose.y - spec.humanoid_pose.y) < 0.05;
    };
    int humanoid = 0;
    for (const Detection& d : a.Humanoids()) {
      EXPECT_TRUE(near_truth(d)) << "seed " << seed << ": clutter taken for the humanoid, fit "
                                 << d.best.fit.fit;
      EXPECT_GE(d.best.fit.fit, gated.min_humanoid_fit);
      EXPECT_EQ(d.refused_by, Refusal::kNone);
      humanoid += near_truth(d) ? 1 : 0;
    }
    for (const Detection& d : a.detections) {
      if (!d.is_humanoid) EXPECT_NE(d.refused_by, Refusal::kNone) << "seed " << seed;
    }
    EXPECT_EQ(humanoid, 1) << "seed " << seed;
    // Humanoids come first, whatever clutter scored: the first detection is the humanoid.
    ASSERT_FALSE(a.detections.empty());
    EXPECT_TRUE(a.detections.front().is_humanoid) << "seed " << seed;
    EXPECT_TRUE(near_truth(a.detections.front())) << "seed " << seed;
    double humanoid_score = 0.0;
    for (const Detection& d : a.Humanoids()) humanoid_score = d.best.score;
    for (const Detection& d : b.Humanoids()) {
      if (near_truth(d)) continue;
      ++clutter_by_score;
      outscored += d.best.score > humanoid_score ? 1 : 0;
      EXPECT_LT(d.best.fit.fit, gated.min_humanoid_fit) << "seed " << seed;
      // With the gate the same cluster is refused by its fit, and says so.
      for (const Detection& g : a.detections) {
        if (g.best.cluster_index != d.best.cluster_index) continue;
        EXPECT_FALSE(g.is_humanoid) << "seed " << seed;
        EXPECT_EQ(g.refused_by, Refusal::kFit) << "seed " << seed;
      }
    }
  }
  EXPECT_GT(clutter_by_score, 0);  // the frames do test the gate,
  EXPECT_GT(outscored, 0);         // and the order.
  gated.min_humanoid_fit = 101.0;
  EXPECT_FALSE(Estimator::Create(gated, templates).ok());
}

// The depth images are asked to choose between a heading and its runner-up only where either
// could make the cluster a humanoid: clutter whose two refined headings both fail the fit gate
// reports the better-fitting one, uncompared, while the humanoid's headings are still compared.
TEST(EstimatorGatesTest, HeadingsOfClutterThatFailsTheFitEitherWayAreNotCompared) {
  const std::vector<VoxelTemplate> templates = {ModelTemplate("standing"),
                                                ModelTemplate("right_arm_raised")};
  // A Nao 1.5 m away among four objects, some of which pass the score and fail the fit.
  FrameSpec spec;
  spec.preset = "standing";
  spec.humanoid_pose = Pose2D{1.5, -0.06, DegToRad(888.0)};
  spec.clutter = 4;
  spec.seed = 24;
  const SimulatedFrame frame = *SimulateFrame(spec);
  const EstimatorOptions gated = DefaultEstimatorOptions();
  EstimatorOptions every = gated;  // no fit gate: every close runner-up is compared.
  every.min_humanoid_fit = 0.0;
  const auto estimate = [&](const EstimatorOptions& o) {
    return *Estimator::Create(o, templates).value()->EstimateDepth(frame.depth, spec.intrinsics);
  };
  const auto near_truth = [&](const Candidate& c) {
    return std::hypot(c.pose.x - spec.humanoid_pose.x, c.pose.y - spec.humanoid_pose.y) < 0.1;
  };
  // A refined candidate whose refined runner-up was close enough in score to be compared.
  const double window = gated.refine.runner_up_score_window;
  const auto close_runner_up = [&](const Candidate& c) {
    return c.refined && c.has_runner_up && std::abs(c.score - c.runner_up_score) <= window;
  };

  const Estimate a = estimate(gated);
  int uncompared = 0, humanoid_compared = 0;
  for (const Candidate& c : a.candidates) {
    if (!close_runner_up(c)) continue;
    if (near_truth(c)) {
      humanoid_compared += c.heading_log_likelihood_sigma > 0.0 ? 1 : 0;
      continue;
    }
    if (std::max(c.fit.fit, c.runner_up_fit.fit) >= gated.min_humanoid_fit) continue;
    ++uncompared;
    EXPECT_EQ(c.heading_log_likelihood_sigma, 0.0) << c.template_name << " " << c.cluster_index;
    EXPECT_GE(c.fit.fit, c.runner_up_fit.fit) << "the better-fitting heading is reported";
  }
  EXPECT_GT(uncompared, 0);  // the frame does have such clutter,
  EXPECT_GT(humanoid_compared, 0);
  ASSERT_FALSE(a.Humanoids().empty());
  EXPECT_LT(std::hypot(a.Humanoids().front().best.pose.x - spec.humanoid_pose.x,
                       a.Humanoids().front().best.pose.y - spec.humanoid_pose.y),
            0.05);

  // Without the gate the same clutter's headings are compared by the depth images.
  const Estimate b = estimate(every);
  int compared = 0;
  for (const Candidate& c : b.candidates) {
    if (!close_runner_up(c) || near_truth(c)) continue;
    compared += c.heading_log_likelihood_sigma > 0.0 ? 1 : 0;
  }
  EXPECT_GT(compared, 0);
}

// Clutter that passes the score and the fit while its pose covers little of the template is no
// humanoid (min_humanoid_evidence); the robot of the same frame stays one, and so does the
// clutter when the previous frame's humanoid stood on it (the held cluster keeps its
// hysteresis).
TEST(EstimatorGatesTest, ClutterCoveringLittleOfTheTemplateIsNoHumanoid) {
  // A random scene drawn as bench/cluster_choice_bench.cc draws them: a Nao 1.2 m away among
  // eight objects, the sensor 0.64 m high looking 9.3 degrees down (one that has such clutter
  // with gcc's arithmetic and with clang's).
  FrameSpec spec;
  spec.preset = "standing";
  spec.humanoid_pose = Pose2D{1.1966014749734613, 0.041848162547198656, -2.1801548237402804};
  spec.sensor_height_m = 0.64478833920793921;
  spec.sensor_pitch_rad = DegToRad(9.3346015294955098);
  spec.clutter = 8;
  spec.seed = 5112;
  spec.noise_correlated_share = 0.9;
  const SimulatedFrame frame = *SimulateFrame(spec);
  const std::vector<VoxelTemplate> templates = {ModelTemplate("standing"),
                                                ModelTemplate("right_arm_raised")};
  const EstimatorOptions gated = DefaultEstimatorOptions();
  ASSERT_GT(gated.min_humanoid_evidence, 0.0);
  EstimatorOptions off = gated;
  off.min_humanoid_evidence = 0.0;
  const auto estimate = [&](const EstimatorOptions& o, const FramePrior* prior) {
    return *Estimator::Create(o, templates)
                .value()
                ->EstimateDepth(frame.depth, spec.intrinsics, prior);
  };
  const auto miss = [&](const Detection& d) {
    return std::hypot(d.best.pose.x - spec.humanoid_pose.x, d.best.pose.y - spec.humanoid_pose.y);
  };

  // Without the gate a box passes: score and fit, but little of the template covered.
  const Estimate before = estimate(off, nullptr);
  const Detection* clutter = nullptr;  // in before.detections: valid while `before` is.
  for (const Detection& d : before.Humanoids()) {
    if (miss(d) >= 0.3) clutter = &d;
  }
  ASSERT_NE(clutter, nullptr);
  EXPECT_GE(clutter->best.score, gated.score_threshold);
  EXPECT_GE(clutter->best.fit.fit, gated.min_humanoid_fit);
  EXPECT_LT(HumanoidEvidenceShare(clutter->best), gated.min_humanoid_evidence);

  // With it the same detection is refused, and the robot is the one humanoid.
  const Estimate now = estimate(gated, nullptr);
  ASSERT_EQ(now.Humanoids().size(), 1u);
  EXPECT_LT(miss(now.Humanoids().front()), 0.05);
  EXPECT_GE(HumanoidEvidenceShare(now.Humanoids().front().best), gated.min_humanoid_evidence);
  bool refused = false;
  for (const Detection& d : now.detections) {
    if (d.best.cluster_index != clutter->best.cluster_index) continue;
    refused = !d.is_humanoid;
    EXPECT_EQ(d.refused_by, Refusal::kEvidence);
    EXPECT_EQ(d.best.score, clutter->best.score);
    EXPECT_EQ(d.best.fit.fit, clutter->best.fit.fit);
  }
  EXPECT_TRUE(refused);

  // Held: the previous frame's humanoid stood on it.
  FramePrior prior;
  prior.has_pose = true;
  prior.template_name = clutter->best.template_name;
  prior.pose = clutter->best.pose;
  prior.score = clutter->best.score;
  const Estimate held = estimate(gated, &prior);
  bool kept = false;
  for (const Detection& d : held.Humanoids()) kept = kept || miss(d) >= 0.3;
  EXPECT_TRUE(kept);
  EXPECT_EQ(held.tracking.held_cluster, clutter->best.cluster_index);

  // ... unless its track never showed tracked_hold_min_evidence: then it is held to the gate
  // like any other cluster (its lower score threshold stays), and the robot is kept.
  prior.hold_confirmed = false;
  const Estimate unconfirmed = estimate(gated, &prior);
  EXPECT_EQ(unconfirmed.tracking.held_cluster, clutter->best.cluster_index);
  ASSERT_EQ(unconfirmed.Humanoids().size(), 1u);
  EXPECT_LT(miss(unconfirmed.Humanoids().front()), 0.05);
  for (const Detection& d : unconfirmed.detections) {
    if (d.best.cluster_index == clutter->best.cluster_index) {
      EXPECT_EQ(d.refused_by, Refusal::kEvidence);
    }
  }

  EstimatorOptions bad = gated;
  for (const double v : {-0.01, 1.5, std::nan("")}) {
    bad.min_humanoid_evidence = v;
    const Result<std::unique_ptr<Estimator>> e = Estimator::Create(bad, templates);
    ASSERT_FALSE(e.ok()) << v;
    EXPECT_NE(e.error().message.find("min_humanoid_evidence"), std::string::npos) << v;
    bad = gated;
    bad.tracked_hold_min_evidence = v;
    const Result<std::unique_ptr<Estimator>> f = Estimator::Create(bad, templates);
    ASSERT_FALSE(f.ok()) << v;
    EXPECT_NE(f.error().message.find("tracked_hold_min_evidence"), std::string::npos) << v;
    bad = gated;
  }
}

// FramePrior::hold_confirmed as PoseTracker keeps it: a track is confirmed by a frame whose
// humanoid shows EstimatorOptions::tracked_hold_min_evidence, or carried on from a confirmed
// track (or a given initial pose) while the humanoid stands on the cluster the last pose held.
TEST(EstimatorGatesTest, ATrackIsConfirmedByItsEvidenceAndCarriedOnWhereItStood) {
  FrameSpec spec;  // a Nao 1.6 m away, two objects beside it.
  spec.preset = "standing";
  spec.humanoid_pose = Pose2D{1.6, 0.1, 0.6};
  spec.clutter = 2;
  spec.seed = 21;
  const SimulatedFrame frame = *SimulateFrame(spec);
  const std::vector<VoxelTemplate> templates = {ModelTemplate("standing")};
  const auto track = [&](double hold_min_evidence) {
    EstimatorOptions o = DefaultEstimatorOptions();
    o.tracked_hold_min_evidence = hold_min_evidence;
    return Estimator::Create(o, templates).value();
  };

  const std::unique_ptr<Estimator> usual = track(0.05);
  PoseTracker tracker(usual.get());
  const Estimate first = *tracker.EstimateDepth(frame.depth, spec.intrinsics);
  ASSERT_EQ(first.Humanoids().size(), 1u);
  EXPECT_EQ(first.tracking.held_cluster, -1);  // a cold frame.
  EXPECT_GE(HumanoidEvidenceShare(first.Humanoids().front().best), 0.05);
  ASSERT_TRUE(tracker.prior().has_value());
  EXPECT_TRUE(tracker.prior()->hold_confirmed);

  // No frame can show a share of 1.01: the track is not confirmed ...
  const std::unique_ptr<Estimator> strict = track(1.0);
  PoseTracker unconfirmed(strict.get());
  ASSERT_EQ(unconfirmed.EstimateDepth(frame.depth, spec.intrinsics)->Humanoids().size(), 1u);
  ASSERT_TRUE(unconfirmed.prior().has_value());
  EXPECT_FALSE(unconfirmed.prior()->hold_confirmed);
  const Estimate next = *unconfirmed.EstimateDepth(frame.depth, spec.intrinsics);
  EXPECT_EQ(next.tracking.held_cluster, next.Humanoids().front().best.cluster_index);
  EXPECT_FALSE(unconfirmed.prior()->hold_confirmed);

  // ... unless it starts from a given initial pose where the robot stands, and then it stays
  // confirmed frame after frame on that cluster.
  PoseTracker given(strict.get());
  given.SetInitialPose(spec.humanoid_pose);
  for (int i = 0; i < 2; ++i) {
    const Estimate e = *given.EstimateDepth(frame.depth, spec.intrinsics);
    ASSERT_EQ(e.Humanoids().size(), 1u) << i;
    EXPECT_EQ(e.tracking.held_cluster, e.Humanoids().front().best.cluster_index) << i;
    ASSERT_TRUE(given.prior().has_value());
    EXPECT_TRUE(given.prior()->hold_confirmed) << i;
  }
  // A pose given elsewhere (bare floor) confirms nothing it does not hold.
  PoseTracker elsewhere(strict.get());
  elsewhere.SetInitialPose(Pose2D{1.0, -0.8, 0.0});
  const Estimate away = *elsewhere.EstimateDepth(frame.depth, spec.intrinsics);
  ASSERT_EQ(away.Humanoids().size(), 1u);
  EXPECT_EQ(away.tracking.held_cluster, -1);
  EXPECT_FALSE(elsewhere.prior()->hold_confirmed);
}

// ClusterOptions::merge_hidden_min_lift_m: a box standing behind the robot, in its silhouette,
// was merged into the robot's cluster as a limb whose joint the body hides, and its voxels
// lowered every template's score and fit there. Frames 10-12 of frame_bench's walk (the Nao
// 1.5 m away, the same four objects in every frame).
TEST(EstimatorGatesTest, AnObjectStandingBehindTheRobotStaysOutOfItsCluster) {
  const std::vector<VoxelTemplate> templates = {ModelTemplate("standing"),
                                                ModelTemplate("right_arm_raised")};
  const EstimatorOptions now_options = DefaultEstimatorOptions();
  ASSERT_GT(now_options.clusters.merge_hidden_min_lift_m, 0.0);
  EstimatorOptions before_options = now_options;
  before_options.clusters.merge_hidden_min_lift_m = 0.0;
  int merged_frames = 0;
  for (int i = 10; i <= 12; ++i) {
    FrameSpec spec;
    const double phi = kPi + DegToRad(2.5 * i);
    spec.humanoid_pose =
        Pose2D{2.2 + 0.8 * std::cos(phi), 0.8 * std::sin(phi), NormalizeAngle(phi + 0.5 * kPi)};
    spec.clutter = 4;
    spec.seed = 1;
    const SimulatedFrame frame = *SimulateFrame(spec);
    const auto estimate = [&](const EstimatorOptions& o) {
      return *Estimator::Create(o, templates).value()->EstimateDepth(frame.depth, spec.intrinsics);
    };
    // The robot's cluster (nearest the truth) and the standing template's candidate on it.
    struct Seen {
      int points = 0;
      const Candidate* standing = nullptr;
    };
    const auto robot = [&](const Estimate& e) {
      Seen seen;
      int index = -1;
      double nearest = 0.3;
      for (const ClusterSummary& c : e.clusters) {
        const double d = std::hypot(c.centroid.x() - spec.humanoid_pose.x,
                                    c.centroid.y() - spec.humanoid_pose.y);
        if (d < nearest) nearest = d, index = c.index, seen.points = c.points;
      }
      for (const Candidate& c : e.candidates) {
        if (c.cluster_index == index && c.template_name == "standing") seen.standing = &c;
      }
      return seen;
    };
    const Estimate before = estimate(before_options), now = estimate(now_options);
    const Seen b = robot(before), n = robot(now);
    ASSERT_NE(b.standing, nullptr) << "frame " << i;
    ASSERT_NE(n.standing, nullptr) << "frame " << i;
    EXPECT_LE(n.points, b.points) << "frame " << i;
    // Found where it stands either way.
    ASSERT_FALSE(now.Humanoids().empty()) << "frame " << i;
    const Candidate& found = now.Humanoids().front().best;
    EXPECT_LT(std::hypot(found.pose.x - spec.humanoid_pose.x, found.pose.y - spec.humanoid_pose.y),
              0.03)
        << "frame " << i;
    EXPECT_LT(std::abs(RadToDeg(AngleDiff(found.pose.theta, spec.humanoid_pose.theta))), 3.0)
        << "frame " << i;
    if (n.points == b.points) continue;
    // The box left out: the template covers more of the robot's cluster, and little of the
    // template is contradicted any more.
    ++merged_frames;
    EXPECT_GE(n.standing->score, b.standing->score + 5.0) << "frame " << i;
    EXPECT_GE(n.standing->fit.fit, 95.0) << "frame " << i;
    EXPECT_GT(n.standing->fit.fit, b.standing->fit.fit) << "frame " << i;
  }
  EXPECT_GE(merged_frames, 1);

  EstimatorOptions bad = now_options;
  for (const double v : {-0.01, std::nan("")}) {
    bad.clusters.merge_hidden_min_lift_m = v;
    const Result<std::unique_ptr<Estimator>> e = Estimator::Create(bad, templates);
    ASSERT_FALSE(e.ok()) << v;
    EXPECT_NE(e.error().message.find("merge_hidden_min_lift_m"), std::string::npos) << v;
  }
}

// EstimatorOptions::two_points_a_voxel_within_m: a robot 1.5 m away is searched on fewer voxels
// (its lone points' voxels left out) and found where it stands all the same; a cluster beyond the
// distance keeps every voxel with a point.
TEST(EstimatorGatesTest, NearClustersCanBeSearchedOnTheVoxelsOfTwoPoints) {
  FrameSpec spec;
  spec.preset = "standing";
  spec.humanoid_pose = Pose2D{1.5, 0.1, DegToRad(40.0)};
  spec.seed = 5;
  const SimulatedFrame frame = *SimulateFrame(spec);
  const std::vector<VoxelTemplate> templates = {ModelTemplate("standing")};
  const auto run = [&](double within_m) {
    EstimatorOptions o = DefaultEstimatorOptions();
    o.two_points_a_voxel_within_m = within_m;
    return *Estimator::Create(o, templates).value()->EstimateDepth(frame.depth, spec.intrinsics);
  };
  const auto robot_candidate = [&](const Estimate& e) {
    const Candidate* best = nullptr;
    for (const Candidate& c : e.candidates) {
      const double d = std::hypot(c.pose.x - spec.humanoid_pose.x, c.pose.y - spec.humanoid_pose.y);
      if (d < 0.2 && (best == nullptr || c.score > best->score)) best = &c;
    }
    return best;
  };
  const Estimate every = run(0.0), two = run(2.5), beyond = run(1.0);
  const Candidate* a = robot_candidate(every);
  const Candidate* b = robot_candidate(two);
  const Candidate* c = robot_candidate(beyond);
  ASSERT_TRUE(a != nullptr && b != nullptr && c != nullptr);
  EXPECT_LT(b->cluster_voxels, a->cluster_voxels);
  EXPECT_GT(b->cluster_voxels, a->cluster_voxels / 2);  // lone points are the few.
  EXPECT_EQ(c->cluster_voxels, a->cluster_voxels);      // 1.5 m is beyond 1.0 m.
  ASSERT_EQ(two.Humanoids().size(), 1u);
  const Pose2D p = two.Humanoids().front().best.pose;
  EXPECT_LT(std::hypot(p.x - spec.humanoid_pose.x, p.y - spec.humanoid_pose.y), 0.03);
  EXPECT_LT(std::abs(RadToDeg(AngleDiff(p.theta, spec.humanoid_pose.theta))), 3.0);
}

}  // namespace
}  // namespace hpose
