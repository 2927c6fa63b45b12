// The estimator's pre-filters skip only what cannot match: a robot whose top the image border
// cuts off is still searched with the template it shows part of.
#include <gtest/gtest.h>

#include "core/search/estimator.h"
#include "core/sim/frame_simulator.h"
#include "core/sim/humanoid_model.h"

namespace hpose {
namespace {

VoxelTemplate ModelTemplate(const std::string& preset) {
  const HumanoidModel model = *HumanoidModel::FromPreset(preset);
  return *MakeTemplateFromPoints(*model.SampleSurface(0.004), preset, 0.016, preset, "test");
}

int CandidatesOf(const Estimate& e, const std::string& name) {
  int n = 0;
  for (const Candidate& c : e.candidates) n += c.template_name == name;
  return n;
}

TEST(EstimatorGatesTest, RobotCutByTheImageTopIsStillSearchedWithItsTemplate) {
  // Sensor 0.34 m high looking 15 degrees down: at 1 m it sees up to about 0.45 m, so the
  // raised arm (top at 0.64 m) and the head are cut off.
  FrameSpec spec;
  spec.preset = "right_arm_raised";
  spec.humanoid_pose = Pose2D{1.0, 0.0, DegToRad(150.0)};
  spec.sensor_pitch_rad = DegToRad(15.0);
  spec.seed = 11;
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

}  // namespace
}  // namespace hpose
