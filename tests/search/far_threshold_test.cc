// Far clusters cold (EstimatorOptions::far_range_m, far_score_ratio, far_min_evidence): when
// nothing in a frame passes score_threshold, a cluster far from the sensor passes from the lower
// far threshold if its refined pose covers enough of the template, fitting well; its searches go
// on from where they stopped and give the exact optimum; frames where something passes are
// searched as without it.
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "core/search/detection_order.h"
#include "core/search/estimator.h"
#include "core/sim/frame_simulator.h"
#include "tests/search/far_nao_scene.h"
#include "tests/search/model_templates.h"

namespace hpose {
namespace {

using testing::ModelTemplate;

// The far Nao of far_nao_scene.h, found cold only by the far threshold.
using Fixture = testing::FarNaoFrame;

TEST(FarThresholdTest, AFarRobotIsFoundColdOnStrongEvidence) {
  const Fixture f;
  const EstimatorOptions options = f.Options();
  const Estimate e = f.Run(options);
  const std::vector<Detection> humans = e.Humanoids();
  ASSERT_EQ(humans.size(), 1u);
  const Detection& d = humans.front();
  EXPECT_TRUE(f.NearTruth(d)) << d.best.pose.x << " " << d.best.pose.y << " "
                              << RadToDeg(d.best.pose.theta);
  EXPECT_LT(d.best.score, options.score_threshold);
  EXPECT_DOUBLE_EQ(d.score_threshold, options.far_score_ratio * options.score_threshold);
  EXPECT_GE(d.best.score, d.score_threshold);
  EXPECT_TRUE(d.best.refined);
  EXPECT_GE(d.best.fit.fit, options.min_humanoid_fit);
  EXPECT_GE(HumanoidEvidenceShare(d.best), options.far_min_evidence);
  EXPECT_GT(d.best.template_voxels, 0);
  // Nothing else became a humanoid.
  for (const Detection& o : e.detections) {
    if (!f.NearTruth(o)) EXPECT_FALSE(o.is_humanoid);
  }

  // One threshold at every range: not found.
  EstimatorOptions one = options;
  one.far_score_ratio = 1.0;
  const Estimate one_threshold = f.Run(one);
  EXPECT_TRUE(one_threshold.Humanoids().empty());
  for (const Detection& o : one_threshold.detections) {
    if (f.NearTruth(o)) EXPECT_EQ(o.refused_by, Refusal::kScore);
  }
  EstimatorOptions near_only = options;
  near_only.far_range_m = 3.5;  // the robot's cluster is nearer than this.
  const Estimate near_search = f.Run(near_only);
  EXPECT_TRUE(near_search.Humanoids().empty());
  // The evidence gate: the same optimum, refused when the evidence asked for is more than it has.
  EstimatorOptions strict = options;
  strict.far_min_evidence = HumanoidEvidenceShare(d.best) + 0.01;
  const Estimate refused = f.Run(strict);
  EXPECT_TRUE(refused.Humanoids().empty());
  bool seen = false;
  for (const Detection& o : refused.detections) {
    if (!f.NearTruth(o)) continue;
    seen = true;
    EXPECT_EQ(o.best.score, d.best.score);
    EXPECT_EQ(o.score_threshold, d.score_threshold);
    EXPECT_EQ(o.refused_by, Refusal::kFarEvidence);
  }
  EXPECT_TRUE(seen);
}

// The searches that stopped below score_threshold and went on to the far threshold give what
// searches that compute every optimum give.
TEST(FarThresholdTest, SearchesGoneOnEqualEveryOptimum) {
  const Fixture f;
  const EstimatorOptions options = f.Options();
  EstimatorOptions full = options;
  full.stop_below_threshold = false;
  const Estimate a = f.Run(options);
  const Estimate b = f.Run(full);
  int compared = 0;
  for (const Candidate& x : a.candidates) {
    if (x.stopped_below_threshold) continue;
    for (const Candidate& y : b.candidates) {
      if (y.cluster_index != x.cluster_index || y.template_name != x.template_name) continue;
      EXPECT_EQ(x.lattice_pose.x, y.lattice_pose.x) << x.template_name;
      EXPECT_EQ(x.lattice_pose.y, y.lattice_pose.y) << x.template_name;
      EXPECT_EQ(x.lattice_pose.theta, y.lattice_pose.theta) << x.template_name;
      EXPECT_EQ(x.score, y.score) << x.template_name;
      EXPECT_EQ(x.pose.x, y.pose.x) << x.template_name;
      EXPECT_EQ(x.has_runner_up, y.has_runner_up) << x.template_name;
      ++compared;
    }
  }
  EXPECT_GE(compared, 2);  // both templates on the robot's cluster.
  // The same verdict and pose.
  ASSERT_EQ(b.Humanoids().size(), 1u);
  ASSERT_EQ(a.Humanoids().size(), 1u);
  EXPECT_EQ(a.Humanoids().front().best.pose.x, b.Humanoids().front().best.pose.x);
  EXPECT_EQ(a.Humanoids().front().score_threshold, b.Humanoids().front().score_threshold);
}

// A frame whose humanoid passes score_threshold: the far clusters are searched as without the
// far threshold (nothing goes on below it).
TEST(FarThresholdTest, AFrameWithAHumanoidIsSearchedAsWithout) {
  Fixture f;
  f.spec.humanoid_pose = Pose2D{1.6, 0.1, DegToRad(120.0)};
  f.Simulate();
  const EstimatorOptions options = f.Options();
  EstimatorOptions one = options;
  one.far_score_ratio = 1.0;
  const Estimate a = f.Run(options);
  const Estimate b = f.Run(one);
  ASSERT_EQ(a.Humanoids().size(), 1u);
  EXPECT_TRUE(f.NearTruth(a.Humanoids().front()));
  ASSERT_EQ(a.candidates.size(), b.candidates.size());
  for (size_t i = 0; i < a.candidates.size(); ++i) {
    EXPECT_EQ(a.candidates[i].pose.x, b.candidates[i].pose.x) << i;
    EXPECT_EQ(a.candidates[i].score, b.candidates[i].score) << i;
    EXPECT_EQ(a.candidates[i].stopped_below_threshold, b.candidates[i].stopped_below_threshold)
        << i;
    EXPECT_EQ(a.candidates[i].bounds_evaluated, b.candidates[i].bounds_evaluated) << i;
  }
  for (const Detection& d : a.detections) EXPECT_EQ(d.score_threshold, options.score_threshold);
}

// Clutter alone, far away: searched on below score_threshold, and no humanoid.
TEST(FarThresholdTest, FarClutterAloneIsNoHumanoid) {
  Fixture f;
  f.spec.humanoid_pose = Pose2D{30.0, 0.0, 0.0};  // out of range: floor and clutter only.
  f.spec.clutter = 6;
  f.Simulate();
  const Estimate e = f.Run(f.Options());
  EXPECT_TRUE(e.Humanoids().empty());
  int far_searched = 0;
  for (const Detection& d : e.detections) far_searched += d.score_threshold < 50.0;
  EXPECT_GT(far_searched, 0);  // the far threshold was tried on the clutter.
}

TEST(FarThresholdTest, BadOptionsAreRefusedByName) {
  const std::vector<VoxelTemplate> templates = {ModelTemplate("standing")};
  const auto error_of = [&](const EstimatorOptions& o) {
    const Result<std::unique_ptr<Estimator>> e = Estimator::Create(o, templates);
    return e.ok() ? std::string() : e.error().message;
  };
  EstimatorOptions o = DefaultEstimatorOptions();
  for (double v : {-0.1, 1.5, std::nan("")}) {
    o = DefaultEstimatorOptions();
    o.far_score_ratio = v;
    EXPECT_NE(error_of(o).find("far_score_ratio"), std::string::npos) << v;
    o = DefaultEstimatorOptions();
    o.far_min_evidence = v + (v > 1.0 ? 0.0 : -1.0);
    EXPECT_NE(error_of(o).find("far_min_evidence"), std::string::npos) << v;
  }
  o = DefaultEstimatorOptions();
  o.far_range_m = -1.0;
  EXPECT_NE(error_of(o).find("far_range_m"), std::string::npos);
  o.far_range_m = std::nan("");
  EXPECT_NE(error_of(o).find("far_range_m"), std::string::npos);
  o.far_range_m = std::numeric_limits<double>::infinity();  // no far clusters: valid.
  EXPECT_EQ(error_of(o), "");
  o = DefaultEstimatorOptions();
  for (double v : {-0.5, std::nan("")}) {
    o.two_points_a_voxel_within_m = v;
    EXPECT_NE(error_of(o).find("two_points_a_voxel_within_m"), std::string::npos) << v;
  }
  o.two_points_a_voxel_within_m = 0.0;  // off: valid.
  EXPECT_EQ(error_of(o), "");
}

}  // namespace
}  // namespace hpose
