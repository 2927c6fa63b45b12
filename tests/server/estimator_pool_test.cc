// The gRPC calls' estimators: pooled ones and those made for a subset of the templates share the
// models the pool made with its first, and estimate as an estimator of their own would.
#include "server/estimator_pool.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <string>
#include <thread>
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

// A tall body's templates are searched on coarser voxels, chosen from the whole set (28 mm for
// the 1.23 m body's two); a subset is searched at the same edge, not at the one it would give
// alone (26 mm without the raised arm), so a template's results do not depend on which others a
// call asks for, and the subset shares the pool's models.
TEST(EstimatorPoolTest, SubsetsOfATallBodySearchAtTheWholeSetsEdge) {
  const std::vector<VoxelTemplate> tpls = {ModelTemplate("standing", "tall"),
                                           ModelTemplate("right_arm_raised", "tall")};
  std::unique_ptr<EstimatorPool> pool =
      std::move(EstimatorPool::Create(DefaultEstimatorOptions(), tpls, 2).value());
  EXPECT_NEAR(pool->options().lattice.resolution_m, 0.028, 1e-12);
  EXPECT_FALSE(pool->options().resolution_from_templates);
  EXPECT_NEAR(Estimator::Create(DefaultEstimatorOptions(), {tpls[0]})
                  .value()
                  ->options()
                  .lattice.resolution_m,
              0.026, 1e-12);

  FrameSpec spec;
  spec.body = "tall";
  spec.humanoid_pose = Pose2D{2.4, 0.3, DegToRad(-30.0)};
  spec.clutter = 2;
  spec.seed = 8;
  const SimulatedFrame frame = *SimulateFrame(spec);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(1);
  const Result<Estimate> subset =
      pool->EstimateDepth(frame.depth, spec.intrinsics, {"standing"}, deadline);
  ASSERT_TRUE(subset.ok()) << subset.error().message;
  EstimatorOptions at_28 = DefaultEstimatorOptions();
  at_28.resolution_from_templates = false;
  at_28.lattice.resolution_m = 0.028;
  const Estimate own =
      *Estimator::Create(at_28, {tpls[0]}).value()->EstimateDepth(frame.depth, spec.intrinsics);
  ASSERT_FALSE(own.Humanoids().empty());
  ASSERT_EQ(subset->candidates.size(), own.candidates.size());
  for (size_t i = 0; i < own.candidates.size(); ++i) {
    EXPECT_EQ(subset->candidates[i].lattice_pose.x, own.candidates[i].lattice_pose.x) << i;
    EXPECT_EQ(subset->candidates[i].lattice_pose.theta, own.candidates[i].lattice_pose.theta) << i;
    EXPECT_EQ(subset->candidates[i].score, own.candidates[i].score) << i;
  }
  const Pose2D p = own.Humanoids().front().best.pose;
  EXPECT_LT(std::hypot(p.x - spec.humanoid_pose.x, p.y - spec.humanoid_pose.y), 0.01);
}

// The warm-up estimates a frame with the estimators of the slots lent first, as many as asked,
// and leaves nothing behind: calls after it give what a pool that never warmed up gives, with
// every slot, warmed or not, in use at once too.
TEST(EstimatorPoolTest, WarmingUpChangesNoEstimate) {
  const EstimatorOptions options = DefaultEstimatorOptions();
  const std::vector<VoxelTemplate> tpls = {ModelTemplate("standing"),
                                           ModelTemplate("right_arm_raised")};
  std::unique_ptr<EstimatorPool> cold = std::move(EstimatorPool::Create(options, tpls, 2).value());
  std::unique_ptr<EstimatorPool> warm = std::move(EstimatorPool::Create(options, tpls, 3).value());
  FrameSpec spec;
  spec.humanoid_pose = Pose2D{2.1, 0.2, DegToRad(-120.0)};
  spec.sensor_height_m = 0.6;
  spec.sensor_pitch_rad = DegToRad(12.0);
  spec.clutter = 3;
  spec.seed = 9;
  const SimulatedFrame frame = *SimulateFrame(spec);
  FrameSpec other = spec;
  other.humanoid_pose = Pose2D{1.3, -0.2, DegToRad(45.0)};
  other.seed = 10;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(1);
  const SimulatedFrame other_frame = *SimulateFrame(other);
  // Two of its three slots.
  EXPECT_EQ(warm->WarmUp(other_frame.depth, other.intrinsics, deadline, 2), 2);

  const Estimate reference = *cold->EstimateDepth(frame.depth, spec.intrinsics, {}, deadline);
  ASSERT_FALSE(reference.Humanoids().empty());
  // All three slots at once (two warmed, one not), each estimating the frame.
  std::vector<Result<Estimate>> results(3, MakeError(ErrorCode::kInternal, "not run"));
  std::vector<std::thread> calls;
  for (int i = 0; i < 3; ++i) {
    calls.emplace_back(
        [&, i] { results[i] = warm->EstimateDepth(frame.depth, spec.intrinsics, {}, deadline); });
  }
  for (std::thread& t : calls) t.join();
  for (const Result<Estimate>& r : results) {
    ASSERT_TRUE(r.ok()) << r.error().message;
    ASSERT_EQ(r->candidates.size(), reference.candidates.size());
    for (size_t i = 0; i < reference.candidates.size(); ++i) {
      const Candidate& a = r->candidates[i];
      const Candidate& b = reference.candidates[i];
      EXPECT_EQ(a.template_name, b.template_name) << i;
      EXPECT_EQ(a.pose.x, b.pose.x) << i;
      EXPECT_EQ(a.pose.y, b.pose.y) << i;
      EXPECT_EQ(a.pose.theta, b.pose.theta) << i;
      EXPECT_EQ(a.score, b.score) << i;
    }
  }
  // Asked for more slots than it has: all three; for none, none.
  EXPECT_EQ(warm->WarmUp(other_frame.depth, other.intrinsics, deadline, 8), 3);
  EXPECT_EQ(warm->WarmUp(other_frame.depth, other.intrinsics, deadline, 0), 0);
}

// A call whose deadline passes while every slot is taken is refused; the slots come back after
// each call, whether it succeeded or failed.
TEST(EstimatorPoolTest, BusySlotsRefuseACallAtItsDeadlineAndEveryCallGivesItsSlotBack) {
  const std::vector<VoxelTemplate> tpls = {ModelTemplate("standing")};
  std::unique_ptr<EstimatorPool> pool =
      std::move(EstimatorPool::Create(DefaultEstimatorOptions(), tpls, 1).value());
  FrameSpec spec;
  spec.seed = 3;
  const SimulatedFrame frame = *SimulateFrame(spec);
  const auto later = [] { return std::chrono::steady_clock::now() + std::chrono::minutes(1); };
  // Failed calls (a template it does not hold, an empty frame) give the slot back.
  EXPECT_EQ(pool->EstimateDepth(frame.depth, spec.intrinsics, {"waving"}, later()).error().code,
            ErrorCode::kNotFound);
  DepthImage empty = frame.depth;
  std::fill(empty.mm.begin(), empty.mm.end(), 0);
  EXPECT_FALSE(pool->EstimateDepth(empty, spec.intrinsics, {}, later()).ok());
  EXPECT_TRUE(pool->EstimateDepth(frame.depth, spec.intrinsics, {}, later()).ok());
  // Its only slot held by the warm-up of another thread: a call with a past deadline is refused.
  std::atomic<bool> warming{true};
  std::thread warm_up([&] {
    EXPECT_EQ(pool->WarmUp(frame.depth, spec.intrinsics, later(), 4), 1);
    warming = false;
  });
  // The warm-up takes a while; a call meanwhile, with no time to wait, is refused or (if it
  // was done already) served.
  const Result<Estimate> now =
      pool->EstimateDepth(frame.depth, spec.intrinsics, {}, std::chrono::steady_clock::now());
  warm_up.join();
  if (!now.ok()) EXPECT_EQ(now.error().code, ErrorCode::kUnavailable);
  EXPECT_FALSE(warming);
  EXPECT_TRUE(pool->EstimateDepth(frame.depth, spec.intrinsics, {}, later()).ok());
}

}  // namespace
}  // namespace hpose::server
