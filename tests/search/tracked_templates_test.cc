// A tracked stream refines a template other than the previous frame's on the held cluster only
// when its search score comes near that template's (EstimatorOptions::
// tracked_other_template_margin): the stream's humanoid is the same with it as with every
// template refined, and a robot that changes posture gets the other template in that frame.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/search/pose_tracker.h"
#include "core/sim/frame_simulator.h"
#include "core/sim/humanoid_model.h"
#include "tests/search/model_templates.h"

namespace hpose {
namespace {

using testing::ModelTemplate;

std::vector<VoxelTemplate> Templates() {
  return {ModelTemplate("standing"), ModelTemplate("right_arm_raised")};
}

SimulatedFrame Frame(const std::string& preset, const Pose2D& pose, std::uint64_t seed) {
  FrameSpec spec;
  spec.preset = preset;
  spec.humanoid_pose = pose;
  spec.clutter = 3;
  spec.seed = seed;
  return *SimulateFrame(spec);
}

EstimatorOptions Options(double margin) {
  EstimatorOptions o = DefaultEstimatorOptions();
  o.use_fixed_floor = true;
  o.fixed_floor = Frame("standing", {1.5, 0.0, 0.0}, 1).sensor_mount;
  o.tracked_other_template_margin = margin;
  return o;
}

bool SamePose(const Pose2D& a, const Pose2D& b) {
  return a.x == b.x && a.y == b.y && a.theta == b.theta;
}

// The candidate of `tpl` on `cluster`, or null.
const Candidate* CandidateOf(const Estimate& e, int cluster, const std::string& tpl) {
  for (const Candidate& c : e.candidates) {
    if (c.cluster_index == cluster && c.template_name == tpl) return &c;
  }
  return nullptr;
}

struct Step {
  std::string preset;
  Pose2D pose;
};

// Streams `steps` through two trackers, one leaving far-behind templates unrefined (the
// default margin) and one refining every template; checks that both give the same humanoid,
// template and pose in every frame. Counts in `left` the frames in which the first left the
// other template unrefined on the humanoid's cluster.
void StreamBoth(const std::vector<Step>& steps, std::vector<std::string>* chosen, int* left) {
  const auto leaving = std::move(Estimator::Create(Options(3.0), Templates()).value());
  const auto refining = std::move(Estimator::Create(Options(-1.0), Templates()).value());
  PoseTracker a(leaving.get());
  PoseTracker b(refining.get());
  const Intrinsics intrinsics = FrameSpec().intrinsics;
  for (size_t k = 0; k < steps.size(); ++k) {
    const SimulatedFrame frame = Frame(steps[k].preset, steps[k].pose, 20 + k);
    const Estimate ea = *a.EstimateDepth(frame.depth, intrinsics);
    const Estimate eb = *b.EstimateDepth(frame.depth, intrinsics);
    const std::string where = "frame " + std::to_string(k);
    ASSERT_EQ(ea.Humanoids().size(), 1u) << where;
    ASSERT_EQ(eb.Humanoids().size(), 1u) << where;
    const Candidate& ha = ea.Humanoids().front().best;
    const Candidate& hb = eb.Humanoids().front().best;
    EXPECT_EQ(ha.template_name, hb.template_name) << where;
    EXPECT_TRUE(ha.refined) << where;
    EXPECT_TRUE(SamePose(ha.pose, hb.pose)) << where;
    EXPECT_LT(std::hypot(ha.pose.x - steps[k].pose.x, ha.pose.y - steps[k].pose.y), 0.03) << where;
    EXPECT_LT(std::abs(AngleDiff(ha.pose.theta, steps[k].pose.theta)), DegToRad(5.0)) << where;
    chosen->push_back(ha.template_name);
    // Every template refined where the search did not stop, in the stream that refines all.
    for (const Candidate& c : eb.candidates) {
      EXPECT_EQ(c.refined, !c.stopped_below_threshold) << where << " " << c.template_name;
    }
    const std::string other = ha.template_name == "standing" ? "right_arm_raised" : "standing";
    const Candidate* oa = CandidateOf(ea, ha.cluster_index, other);
    const Candidate* ob = CandidateOf(eb, ha.cluster_index, other);
    ASSERT_NE(oa, nullptr) << where;
    ASSERT_NE(ob, nullptr) << where;
    EXPECT_EQ(oa->score, ob->score) << where;  // the same search.
    // The detection says in which points its margin over the other template is.
    EXPECT_EQ(ea.Humanoids().front().template_margin_in_fit, oa->refined) << where;
    EXPECT_EQ(eb.Humanoids().front().template_margin_in_fit, ob->refined) << where;
    if (oa->refined || oa->stopped_below_threshold) continue;
    // Left unrefined: only in a tracked frame, on the previous frame's template's lead, the
    // search pose reported as is and no runner-up searched.
    ++*left;
    EXPECT_TRUE(ea.tracking.tracked) << where;
    EXPECT_EQ(ea.tracking.prior_template, ha.template_name) << where;
    EXPECT_LT(oa->score, ha.score - 3.0) << where;
    EXPECT_TRUE(SamePose(oa->pose, oa->lattice_pose)) << where;
    EXPECT_FALSE(oa->has_runner_up) << where;
    EXPECT_TRUE(ob->refined) << where;
    EXPECT_LT(ob->fit.fit, hb.fit.fit) << where << ": the template refined anyway fits worse";
  }
}

// A robot walking and turning in place of its template's posture: the other template, far
// behind in score, is left unrefined in the tracked frames; the humanoid is the same.
TEST(TrackedTemplatesTest, AFarBehindTemplateIsLeftUnrefinedWithTheSameHumanoid) {
  std::vector<Step> steps;
  for (int k = 0; k < 5; ++k) {
    steps.push_back({"standing", {1.4 + 0.03 * k, -0.1 + 0.02 * k, DegToRad(-70.0 + 3.0 * k)}});
  }
  std::vector<std::string> chosen;
  int left = 0;
  StreamBoth(steps, &chosen, &left);
  for (const std::string& name : chosen) EXPECT_EQ(name, "standing");
  std::printf("the other template was left unrefined in %d of %zu frames\n", left, steps.size());
  EXPECT_GE(left, 2);
}

// A robot that raises its arm while tracked as standing: the raised-arm template's score comes
// up, so it is refined and taken in the frame that first shows the arm; then standing, behind
// it, is the one left unrefined.
TEST(TrackedTemplatesTest, APostureChangeIsSeenInTheFrameThatShowsIt) {
  std::vector<Step> steps;
  for (int k = 0; k < 5; ++k) {
    steps.push_back({k < 2 ? "standing" : "right_arm_raised",
                     {1.6 + 0.02 * k, 0.2, DegToRad(-120.0 + 2.0 * k)}});
  }
  std::vector<std::string> chosen;
  int left = 0;
  StreamBoth(steps, &chosen, &left);
  ASSERT_EQ(chosen.size(), steps.size());
  EXPECT_EQ(chosen[0], "standing");
  EXPECT_EQ(chosen[1], "standing");
  for (size_t k = 2; k < chosen.size(); ++k) EXPECT_EQ(chosen[k], "right_arm_raised") << k;
  // Once the raised arm is the previous frame's template, standing is the one left behind.
  EXPECT_GE(left, 1);
}

TEST(TrackedTemplatesTest, MarginOutOfRangeIsRefused) {
  EstimatorOptions o = DefaultEstimatorOptions();
  o.tracked_other_template_margin = 101.0;
  EXPECT_FALSE(Estimator::Create(o, Templates()).ok());
  o.tracked_other_template_margin = std::nan("");
  EXPECT_FALSE(Estimator::Create(o, Templates()).ok());
  o.tracked_other_template_margin = -1.0;  // off
  EXPECT_TRUE(Estimator::Create(o, Templates()).ok());
}

}  // namespace
}  // namespace hpose
