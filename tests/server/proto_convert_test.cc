#include "server/proto_convert.h"

#include <gtest/gtest.h>

#include <utility>
#include <vector>

#include <cmath>

namespace hpose::server {
namespace {

v1::DepthImage SmallDepth() {
  DepthImage d(4, 3);
  for (size_t i = 0; i < d.mm.size(); ++i) d.mm[i] = static_cast<std::uint16_t>(1000 + 300 * i);
  Intrinsics k;
  k.width = 4;
  k.height = 3;
  k.fx = k.fy = 5.0;
  k.cx = 2.0;
  k.cy = 1.5;
  v1::DepthImage out;
  DepthToProto(d, k, &out);
  return out;
}

TEST(ProtoConvertTest, DepthRoundTripsLittleEndian) {
  const v1::DepthImage msg = SmallDepth();
  ASSERT_EQ(msg.data().size(), 24u);
  EXPECT_EQ(static_cast<unsigned char>(msg.data()[0]), 1000 & 0xff);
  Intrinsics k;
  Result<DepthImage> back = DepthFromProto(msg, &k);
  ASSERT_TRUE(back.ok()) << back.error().ToString();
  EXPECT_EQ(back->at(3, 2), 1000 + 300 * 11);
  EXPECT_EQ(k.width, 4);
  EXPECT_DOUBLE_EQ(k.cy, 1.5);
}

TEST(ProtoConvertTest, RejectsBadDepthWithTheField) {
  Intrinsics k;
  v1::DepthImage m = SmallDepth();
  m.mutable_data()->pop_back();
  EXPECT_NE(DepthFromProto(m, &k).error().message.find("depth.data"), std::string::npos);
  m = SmallDepth();
  m.mutable_intrinsics()->set_cx(NAN);
  EXPECT_NE(DepthFromProto(m, &k).error().message.find("cx"), std::string::npos);
  m = SmallDepth();
  m.mutable_intrinsics()->set_fx(INFINITY);
  EXPECT_NE(DepthFromProto(m, &k).error().message.find("fx"), std::string::npos);
  m = SmallDepth();
  m.mutable_intrinsics()->set_height(4);
  EXPECT_NE(DepthFromProto(m, &k).error().message.find("does not match"), std::string::npos);
  m = SmallDepth();
  m.clear_intrinsics();
  EXPECT_NE(DepthFromProto(m, &k).error().message.find("missing"), std::string::npos);
  m = SmallDepth();
  m.set_width(0);
  EXPECT_EQ(DepthFromProto(m, &k).error().code, ErrorCode::kInvalidArgument);
}

TEST(ProtoConvertTest, CloudChecksLength) {
  v1::PointCloud c;
  EXPECT_EQ(CloudFromProto(c).error().code, ErrorCode::kInvalidArgument);
  for (float v : {1.f, 2.f, 3.f, 4.f}) c.add_xyz(v);
  EXPECT_NE(CloudFromProto(c).error().message.find("multiple of 3"), std::string::npos);
  c.add_xyz(5.f);
  c.add_xyz(6.f);
  Result<PointCloud> ok = CloudFromProto(c);
  ASSERT_TRUE(ok.ok());
  ASSERT_EQ(ok->size(), 2u);
  EXPECT_FLOAT_EQ(ok->points[1].z(), 6.f);
}

TEST(ProtoConvertTest, EstimateCarriesPoseIn3DAndMargins) {
  Estimate e;
  Candidate c;
  c.template_name = "standing";
  c.pose = {1.0, -0.2, 2.5};
  c.score = 70.0;
  c.has_runner_up = true;
  c.runner_up_score = 60.0;
  c.runner_up_pose = {1.0, -0.2, -0.6};
  c.refined = true;
  c.fit.fit = 91.5;
  c.fit.in_view = 0.625;
  Detection d;
  d.best = c;
  d.second_template = "right_arm_raised";
  d.template_margin = 4.0;
  d.template_margin_kind = MarginKind::kFit;
  d.is_humanoid = true;
  d.score_threshold = 35.0;
  e.candidates = {c};
  e.detections = {d};
  v1::DepthTemplateResult out;
  EstimateToProto(e, &out);
  ASSERT_TRUE(out.humanoid_found());
  const v1::Candidate& p = out.best().best();
  EXPECT_DOUBLE_EQ(p.runner_up_margin(), 10.0);
  EXPECT_DOUBLE_EQ(out.best().template_margin(), 4.0);
  EXPECT_EQ(out.best().template_margin_kind(), v1::TEMPLATE_MARGIN_FIT);
  EXPECT_DOUBLE_EQ(out.best().score_threshold(), 35.0);
  EXPECT_NEAR(p.pose_3d().orientation().z(), std::sin(1.25), 1e-12);
  EXPECT_NEAR(p.pose_3d().orientation().w(), std::cos(1.25), 1e-12);
  EXPECT_DOUBLE_EQ(p.pose_3d().position().y(), -0.2);
  EXPECT_EQ(out.best().refused_by(), v1::REFUSAL_NONE);
  EXPECT_DOUBLE_EQ(p.fit().fit(), 91.5);
  ASSERT_TRUE(p.fit().has_in_view());
  EXPECT_DOUBLE_EQ(p.fit().in_view(), 0.625);
  // A candidate left at its lattice pose measured nothing: its share in view is unset, not 1.
  e.detections[0].best.refined = false;
  e.detections[0].best.fit = FitSummary{};
  EstimateToProto(e, &out);
  EXPECT_FALSE(out.best().best().refined());
  EXPECT_FALSE(out.best().best().fit().has_in_view());
  e.detections[0].best = c;
  EXPECT_EQ(out.tracking().height_searches(), 1);
  e.height_passes = 3;
  EstimateToProto(e, &out);
  EXPECT_EQ(out.tracking().height_searches(), 3);
  // A refused cluster says which rule refused it.
  for (const auto& [rule, wire] : std::vector<std::pair<Refusal, v1::Refusal>>{
           {Refusal::kScore, v1::REFUSAL_SCORE},
           {Refusal::kFit, v1::REFUSAL_FIT},
           {Refusal::kEvidence, v1::REFUSAL_EVIDENCE},
           {Refusal::kFarEvidence, v1::REFUSAL_FAR_EVIDENCE},
           {Refusal::kOffFloorCoverage, v1::REFUSAL_OFF_FLOOR_COVERAGE}}) {
    e.detections[0].is_humanoid = false;
    e.detections[0].refused_by = rule;
    EstimateToProto(e, &out);
    EXPECT_FALSE(out.humanoid_found());
    EXPECT_EQ(out.best().refused_by(), wire);
  }

  v1::PoseEstimate pe;
  const Error err = MakeError(ErrorCode::kFailedPrecondition, "no floor: only 3 points");
  FillPoseEstimate(7, 0.5, std::chrono::system_clock::now(), "x", nullptr, &err, &pe);
  EXPECT_EQ(pe.error().code(), "failed_precondition");
  EXPECT_EQ(pe.sequence(), 7u);
  EXPECT_FALSE(pe.has_depth_template());
}

}  // namespace
}  // namespace hpose::server
