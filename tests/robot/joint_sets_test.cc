#include "core/robot/joint_sets.h"

#include <gtest/gtest.h>

namespace hpose {
namespace {

TEST(JointSetsTest, ParsesSetsInDocumentOrder) {
  const std::string yaml =
      "standing: {}\n"
      "right_arm_raised:\n"
      "  j_shoulder_r: -2.5\n"
      "  j_high_arm_r: 0.25\n"
      "mid_step: {j_thigh1_l: 0.3, j_tibia_l: -0.6}\n";
  Result<std::vector<NamedJointSet>> sets = ParseJointSetsYaml(yaml, "poses.yaml");
  ASSERT_TRUE(sets.ok()) << sets.error().message;
  ASSERT_EQ(sets->size(), 3u);
  EXPECT_EQ((*sets)[0].name, "standing");
  EXPECT_TRUE((*sets)[0].joints.empty());
  EXPECT_EQ((*sets)[1].name, "right_arm_raised");
  EXPECT_DOUBLE_EQ((*sets)[1].joints.at("j_shoulder_r"), -2.5);
  EXPECT_DOUBLE_EQ((*sets)[1].joints.at("j_high_arm_r"), 0.25);
  EXPECT_EQ((*sets)[2].name, "mid_step");
  EXPECT_DOUBLE_EQ((*sets)[2].joints.at("j_tibia_l"), -0.6);
}

TEST(JointSetsTest, RejectsBadDocumentsNamingTheProblem) {
  Result<std::vector<NamedJointSet>> r = ParseJointSetsYaml("a: {j1: up}\n", "p.yaml");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("p.yaml"), std::string::npos);
  EXPECT_NE(r.error().message.find("j1"), std::string::npos);
  EXPECT_FALSE(ParseJointSetsYaml("[1, 2]\n", "p.yaml").ok());
  EXPECT_FALSE(ParseJointSetsYaml("a: {j: [\n", "p.yaml").ok());
  EXPECT_FALSE(ParseJointSetsYaml("a: 3\n", "p.yaml").ok());
  EXPECT_FALSE(ParseJointSetsYaml("a b: {}\n", "p.yaml").ok());
  EXPECT_FALSE(ParseJointSetsYaml("a: {j: .nan}\n", "p.yaml").ok());
  EXPECT_EQ(LoadJointSetsFile("/nonexistent/poses.yaml").error().code, ErrorCode::kNotFound);
}

TEST(JointSetsTest, ParsesCommandLineAssignments) {
  JointValues v;
  ASSERT_TRUE(ParseJointAssignment("j_pan=0.5", &v).ok());
  ASSERT_TRUE(ParseJointAssignment("j_tilt=-1e-1", &v).ok());
  EXPECT_DOUBLE_EQ(v.at("j_pan"), 0.5);
  EXPECT_DOUBLE_EQ(v.at("j_tilt"), -0.1);
  EXPECT_FALSE(ParseJointAssignment("j_pan", &v).ok());
  EXPECT_FALSE(ParseJointAssignment("=1", &v).ok());
  EXPECT_FALSE(ParseJointAssignment("j_pan=abc", &v).ok());
  EXPECT_FALSE(ParseJointAssignment("j_pan=1x", &v).ok());
}

}  // namespace
}  // namespace hpose
