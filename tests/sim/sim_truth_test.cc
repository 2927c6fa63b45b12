#include "core/sim/sim_truth.h"

#include <string>
#include <utility>

#include <gtest/gtest.h>

namespace hpose {
namespace {

SimTruth SampleTruth() {
  SimTruth t;
  t.humanoid_preset = "right_arm_raised";
  t.humanoid_height_m = 0.61;
  t.humanoid_pose = {1.25, -0.5, 2.5};
  t.other_humanoids.push_back({{2.0, 0.5, -1.0}, "standing"});
  t.sensor_height_m = 0.34;
  t.sensor_pitch_rad = 0.1;
  t.sensor_roll_rad = -0.05;
  t.intrinsics = Intrinsics::KinectV1(320, 240);
  t.noise_enabled = false;
  t.seed = 18446744073709551615ULL;
  t.clutter_count = 1;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(2.0, 0.3, 0.1);
  t.clutter.push_back(Primitive::Box("box_1", Eigen::Vector3d(0.2, 0.3, 0.2), pose));
  t.frames.push_back({0, "depth_000.png", "cloud_000.pcd", {1.25, -0.5, 2.5}, 77});
  t.frames.push_back({1, "depth_001.png", "cloud_001.pcd", {1.3, -0.5, 2.6}, 78});
  t.command = "hpose simulate --out x";
  return t;
}

TEST(SimTruthTest, RoundTripsThroughJson) {
  const SimTruth t = SampleTruth();
  const Result<SimTruth> back = ParseSimTruthJson(SimTruthToJson(t), "mem");
  ASSERT_TRUE(back.ok()) << back.error().ToString();
  EXPECT_EQ(back->humanoid_preset, t.humanoid_preset);
  EXPECT_DOUBLE_EQ(back->humanoid_pose.theta, 2.5);
  EXPECT_DOUBLE_EQ(back->other_humanoids.at(0).pose.x, 2.0);
  EXPECT_DOUBLE_EQ(back->sensor_roll_rad, -0.05);
  EXPECT_EQ(back->intrinsics.width, 320);
  EXPECT_DOUBLE_EQ(back->intrinsics.fx, t.intrinsics.fx);
  EXPECT_EQ(back->seed, t.seed);
  EXPECT_FALSE(back->noise_enabled);
  ASSERT_EQ(back->clutter.size(), 1u);
  EXPECT_EQ(back->clutter[0].shape, PrimitiveShape::kBox);
  EXPECT_TRUE(back->clutter[0].parent_from_local.isApprox(t.clutter[0].parent_from_local, 1e-12));
  EXPECT_TRUE(back->clutter[0].half_size.isApprox(Eigen::Vector3d(0.1, 0.15, 0.1)));
  ASSERT_EQ(back->frames.size(), 2u);
  EXPECT_EQ(back->frames[1].depth_file, "depth_001.png");
  EXPECT_EQ(back->frames[1].noise_seed, 78u);
  EXPECT_DOUBLE_EQ(back->frames[1].humanoid_pose.theta, 2.6);
  EXPECT_EQ(back->command, t.command);
}

TEST(SimTruthTest, MalformedTextIsDataLoss) {
  for (const std::string text : {"", "{", "{\"format\":\"other\"}", "[1,2]",
                                 "{\"format\":\"hpose-sim-truth\",\"version\":1}"}) {
    const Result<SimTruth> r = ParseSimTruthJson(text, "truth.json");
    ASSERT_FALSE(r.ok()) << text;
    EXPECT_EQ(r.error().code, ErrorCode::kDataLoss);
    EXPECT_NE(r.error().message.find("truth.json"), std::string::npos);
  }
}

// A truth file is drawn (`hpose plot --truth`): a pose or clutter far beyond any room, which made
// the plot's grid loop for ever, is an error naming the number.
TEST(SimTruthTest, PlacesBeyondTenKilometresAreDataLoss) {
  SimTruth far_frame = SampleTruth();
  far_frame.frames[1].humanoid_pose.x = -1e308;
  SimTruth far_other = SampleTruth();
  far_other.other_humanoids[0].pose.y = 2e4;
  SimTruth spun = SampleTruth();
  spun.humanoid_pose.theta = 100.0;
  SimTruth far_clutter = SampleTruth();
  far_clutter.clutter[0].parent_from_local.translation().x() = 1e7;
  const std::pair<SimTruth, std::string> cases[] = {
      {far_frame, "frames[1].x = -1e+308 is not within 10000 m"},
      {far_other, "other_humanoids[0].y = 20000 is not within 10000 m"},
      {spun, "humanoid.theta = 100 is not within 12.5664 rad"},
      {far_clutter, "clutter[0].position_m = [1e+07, 0.3, 0.1] is not within 10000 m"}};
  for (const auto& [truth, message] : cases) {
    const Result<SimTruth> r = ParseSimTruthJson(SimTruthToJson(truth), "truth.json");
    ASSERT_FALSE(r.ok()) << message;
    EXPECT_EQ(r.error().code, ErrorCode::kDataLoss);
    EXPECT_NE(r.error().message.find("truth.json"), std::string::npos) << r.error().message;
    EXPECT_NE(r.error().message.find(message), std::string::npos) << r.error().message;
  }
  SimTruth at_the_edge = SampleTruth();
  at_the_edge.frames[0].humanoid_pose = {1e4, -1e4, -4 * kPi};
  EXPECT_TRUE(ParseSimTruthJson(SimTruthToJson(at_the_edge), "truth.json").ok());
}

}  // namespace
}  // namespace hpose
