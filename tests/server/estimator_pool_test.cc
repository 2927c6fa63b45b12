// The gRPC calls' estimators: pooled ones and those made for a subset of the templates share the
// models the pool made with its first, and estimate as an estimator of their own would.
#include "server/estimator_pool.h"

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/sim/frame_simulator.h"
#include "tests/search/model_templates.h"

namespace hpose::server {
namespace {

using hpose::testing::ModelTemplate;

TEST(EstimatorPoolTest, SubsetsShareThePoolsModelsAndEstimateAsTheirOwn) {
  const EstimatorOptions options = DefaultEstimatorOptions();
  const std::vector<VoxelTemplate> tpls = {ModelTemplate("standing"),
                                           ModelTemplate("right_arm_raised")};
  std::unique_ptr<EstimatorPool> pool = std::move(EstimatorPool::Create(options, tpls, 2).value());
  ASSERT_EQ(pool->models().size(), 2u);
  for (const TemplateModels& m : pool->models()) {
    ASSERT_NE(m.rotations, nullptr);
    ASSERT_NE(m.surface, nullptr);
  }
  EXPECT_EQ(pool->models()[1].rotations->name(), "right_arm_raised");

  FrameSpec spec;
  spec.preset = "right_arm_raised";
  spec.humanoid_pose = Pose2D{1.6, -0.1, DegToRad(60.0)};
  spec.clutter = 2;
  spec.seed = 5;
  const SimulatedFrame frame = *SimulateFrame(spec);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(1);
  const Result<Estimate> subset =
      pool->EstimateDepth(frame.depth, spec.intrinsics, {"right_arm_raised"}, deadline);
  ASSERT_TRUE(subset.ok()) << subset.error().message;
  // The reference: an estimator of that template alone, with models of its own.
  const Estimate own =
      *Estimator::Create(options, {tpls[1]}).value()->EstimateDepth(frame.depth, spec.intrinsics);
  ASSERT_FALSE(own.candidates.empty());
  ASSERT_EQ(subset->candidates.size(), own.candidates.size());
  for (size_t i = 0; i < own.candidates.size(); ++i) {
    const Candidate& a = subset->candidates[i];
    const Candidate& b = own.candidates[i];
    EXPECT_EQ(a.template_name, "right_arm_raised");
    EXPECT_EQ(a.cluster_index, b.cluster_index) << i;
    EXPECT_EQ(a.pose.x, b.pose.x) << i;
    EXPECT_EQ(a.pose.y, b.pose.y) << i;
    EXPECT_EQ(a.pose.theta, b.pose.theta) << i;
    EXPECT_EQ(a.score, b.score) << i;
  }

  const Result<Estimate> unknown =
      pool->EstimateDepth(frame.depth, spec.intrinsics, {"waving"}, deadline);
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.error().code, ErrorCode::kNotFound);
  EXPECT_NE(unknown.error().message.find("waving"), std::string::npos);
}

}  // namespace
}  // namespace hpose::server
