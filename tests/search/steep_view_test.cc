// A sensor high up looking steeply down (FreeSpaceOptions::steep_ray_rad): the rays graze the
// body's sides along their whole height, and without the 3 x 3 nearest depth along steep rays
// the voxels just beside them count as seen through, so a robot that fits well scores below the
// threshold. Mounts without such rays are estimated exactly as before.
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "core/search/estimator.h"
#include "core/sim/frame_simulator.h"
#include "tests/search/model_templates.h"

namespace hpose {
namespace {

using testing::ModelTemplate;

struct Frame {
  FrameSpec spec;
  SimulatedFrame frame;
  std::vector<VoxelTemplate> templates = {ModelTemplate("standing"),
                                          ModelTemplate("right_arm_raised")};

  Frame(double height_m, double pitch_deg, Pose2D pose) {
    spec.preset = "standing";
    spec.humanoid_pose = pose;
    spec.sensor_height_m = height_m;
    spec.sensor_pitch_rad = DegToRad(pitch_deg);
    spec.clutter = 2;
    spec.seed = 4;
    frame = *SimulateFrame(spec);
  }
  // The defaults on the true mount, the free space along steep rays and the floor noise's
  // reach as given.
  Estimate Run(double steep_ray_rad,
               double floor_noise_sigmas = ClusterOptions{}.floor_noise_sigmas) const {
    EstimatorOptions o = DefaultEstimatorOptions();
    o.use_fixed_floor = true;
    o.fixed_floor = frame.sensor_mount;
    o.free_space.steep_ray_rad = steep_ray_rad;
    o.clusters.floor_noise_sigmas = floor_noise_sigmas;
    return *Estimator::Create(o, templates).value()->EstimateDepth(frame.depth, spec.intrinsics);
  }
  bool NearTruth(const Detection& d) const {
    return std::hypot(d.best.pose.x - spec.humanoid_pose.x, d.best.pose.y - spec.humanoid_pose.y) <
               0.05 &&
           std::abs(RadToDeg(AngleDiff(d.best.pose.theta, spec.humanoid_pose.theta))) < 10.0;
  }
};

constexpr double kOff = 4.0;  // above pi/2: no ray is that steep.

TEST(SteepViewTest, ARobotSeenFromAboveIsFound) {
  const Frame f(2.6, 80.0, Pose2D{0.4, 0.1, DegToRad(100.0)});
  const double by_default = FreeSpaceOptions{}.steep_ray_rad;
  const Estimate found = f.Run(by_default);
  const HumanoidView humans = found.Humanoids();
  ASSERT_EQ(humans.size(), 1u);
  EXPECT_TRUE(f.NearTruth(humans.front()));
  EXPECT_GE(humans.front().best.score, 50.0);
  // Every voxel read along the ray through its centre alone: the same robot scores below 50.
  const Estimate without = f.Run(kOff);
  EXPECT_TRUE(without.Humanoids().empty());
  double best_without = 0.0;
  for (const Candidate& c : without.candidates) best_without = std::max(best_without, c.score);
  EXPECT_LT(best_without, 50.0);
}

TEST(SteepViewTest, MountsWithoutSteepRaysAreEstimatedAsBefore) {
  for (const auto& [height, pitch] : {std::pair{0.34, 0.0}, std::pair{1.5, 45.0}}) {
    const Frame f(height, pitch, Pose2D{2.0, -0.2, DegToRad(150.0)});
    const Estimate a = f.Run(FreeSpaceOptions{}.steep_ray_rad);
    const Estimate b = f.Run(kOff);
    ASSERT_EQ(a.candidates.size(), b.candidates.size());
    ASSERT_FALSE(a.candidates.empty());
    for (size_t k = 0; k < a.candidates.size(); ++k) {
      EXPECT_EQ(a.candidates[k].pose.x, b.candidates[k].pose.x);
      EXPECT_EQ(a.candidates[k].pose.theta, b.candidates[k].pose.theta);
      EXPECT_EQ(a.candidates[k].score, b.candidates[k].score);
      EXPECT_EQ(a.candidates[k].free_space_hits, b.candidates[k].free_space_hits);
    }
  }
}

// Under a sensor 2.9 m high the floor is noisy enough in height that its speckle above 4 cm
// joins the robot and the clutter into one cluster too wide to be anything
// (ClusterOptions::floor_noise_sigmas).
TEST(SteepViewTest, ARobotUnderASensorNearTheCeilingHasAClusterOfItsOwn) {
  const Frame f(2.93, 80.0, Pose2D{0.45, 0.02, DegToRad(-110.0)});
  const double steep = FreeSpaceOptions{}.steep_ray_rad;
  const Estimate found = f.Run(steep);
  const HumanoidView humans = found.Humanoids();
  ASSERT_EQ(humans.size(), 1u);
  EXPECT_TRUE(f.NearTruth(humans.front()));
  const Estimate without = f.Run(steep, 0.0);
  EXPECT_TRUE(without.Humanoids().empty());
  for (const Candidate& c : without.candidates) {
    EXPECT_GT(std::hypot(c.pose.x - 0.45, c.pose.y - 0.02), 0.1) << "found without";
  }
}

TEST(SteepViewTest, ANegativeLimitIsRefused) {
  EstimatorOptions o = DefaultEstimatorOptions();
  o.free_space.steep_ray_rad = -0.1;
  const Result<std::unique_ptr<Estimator>> e = Estimator::Create(o, {ModelTemplate("standing")});
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.error().message.find("free_space.steep_ray_rad"), std::string::npos);
  o.free_space.steep_ray_rad = std::nan("");
  EXPECT_FALSE(Estimator::Create(o, {ModelTemplate("standing")}).ok());
}

}  // namespace
}  // namespace hpose
