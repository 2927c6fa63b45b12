// A tracked stream refines a template other than the previous frame's on the held cluster only
// when its search score comes near that template's (EstimatorOptions::
// tracked_other_template_margin): the stream's humanoid is the same with it as with every
// template refined, and a robot that changes posture gets the other template in that frame.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
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

EstimatorOptions Options(double margin, bool stops = true) {
  EstimatorOptions o = DefaultEstimatorOptions();
  o.use_fixed_floor = true;
  o.fixed_floor = Frame("standing", {1.5, 0.0, 0.0}, 1).sensor_mount;
  o.tracked_other_template_margin = margin;
  o.tracked_other_template_stops = stops;
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

// Streams `steps` through three trackers: one leaving far-behind templates unrefined and
// stopping their searches there (the defaults), one leaving them unrefined but proving their
// optima, and one refining every template; checks that all give the same humanoid, template
// and pose in every frame, and the first two the same refinements. Counts in `left` the frames
// in which the first left the other template unrefined on the humanoid's cluster, in `stopped`
// those in which its search stopped.
void StreamAll(const std::vector<Step>& steps, std::vector<std::string>* chosen, int* left,
               int* stopped) {
  const auto leaving = std::move(Estimator::Create(Options(3.0), Templates()).value());
  const auto proving = std::move(Estimator::Create(Options(3.0, false), Templates()).value());
  const auto refining = std::move(Estimator::Create(Options(-1.0), Templates()).value());
  PoseTracker a(leaving.get());
  PoseTracker p(proving.get());
  PoseTracker b(refining.get());
  const Intrinsics intrinsics = FrameSpec().intrinsics;
  for (size_t k = 0; k < steps.size(); ++k) {
    const SimulatedFrame frame = Frame(steps[k].preset, steps[k].pose, 20 + k);
    const Estimate ea = *a.EstimateDepth(frame.depth, intrinsics);
    const Estimate ep = *p.EstimateDepth(frame.depth, intrinsics);
    const Estimate eb = *b.EstimateDepth(frame.depth, intrinsics);
    const std::string where = "frame " + std::to_string(k);
    ASSERT_EQ(ea.Humanoids().size(), 1u) << where;
    ASSERT_EQ(ep.Humanoids().size(), 1u) << where;
    ASSERT_EQ(eb.Humanoids().size(), 1u) << where;
    const Candidate& ha = ea.Humanoids().front().best;
    const Candidate& hp = ep.Humanoids().front().best;
    const Candidate& hb = eb.Humanoids().front().best;
    EXPECT_EQ(ha.template_name, hb.template_name) << where;
    EXPECT_EQ(hp.template_name, hb.template_name) << where;
    EXPECT_TRUE(ha.refined) << where;
    EXPECT_TRUE(SamePose(ha.pose, hb.pose)) << where;
    EXPECT_TRUE(SamePose(hp.pose, hb.pose)) << where;
    EXPECT_LT(std::hypot(ha.pose.x - steps[k].pose.x, ha.pose.y - steps[k].pose.y), 0.03) << where;
    EXPECT_LT(std::abs(AngleDiff(ha.pose.theta, steps[k].pose.theta)), DegToRad(5.0)) << where;
    chosen->push_back(ha.template_name);
    // Every template refined where the search did not stop, in the stream that refines all.
    for (const Candidate& c : eb.candidates) {
      EXPECT_EQ(c.refined, !c.stopped_below_threshold) << where << " " << c.template_name;
    }
    const std::string other = ha.template_name == "standing" ? "right_arm_raised" : "standing";
    const Candidate* oa = CandidateOf(ea, ha.cluster_index, other);
    const Candidate* op = CandidateOf(ep, ha.cluster_index, other);
    const Candidate* ob = CandidateOf(eb, ha.cluster_index, other);
    ASSERT_NE(oa, nullptr) << where;
    ASSERT_NE(op, nullptr) << where;
    ASSERT_NE(ob, nullptr) << where;
    EXPECT_EQ(op->score, ob->score) << where;  // the same search.
    // Stopping the search changes nothing of what is refined, nor the runner-ups.
    EXPECT_EQ(oa->refined, op->refined) << where;
    for (const auto& [x, y] : {std::pair{&ha, &hp}, std::pair{oa, op}}) {
      if (!x->refined) continue;
      EXPECT_EQ(x->score, y->score) << where << " " << x->template_name;
      EXPECT_TRUE(SamePose(x->pose, y->pose)) << where << " " << x->template_name;
      EXPECT_EQ(x->has_runner_up, y->has_runner_up) << where << " " << x->template_name;
      EXPECT_TRUE(SamePose(x->runner_up_pose, y->runner_up_pose))
          << where << " " << x->template_name;
      EXPECT_EQ(x->runner_up_score, y->runner_up_score) << where << " " << x->template_name;
    }
    // The detection says in which points its margin over the other template is.
    const MarginKind kind = ea.Humanoids().front().template_margin_kind;
    EXPECT_EQ(kind, oa->refined                   ? MarginKind::kFit
                    : oa->stopped_below_threshold ? MarginKind::kScoreAtLeast
                                                  : MarginKind::kScore)
        << where;
    EXPECT_EQ(ep.Humanoids().front().template_margin_kind,
              op->refined ? MarginKind::kFit : MarginKind::kScore)
        << where;
    if (oa->refined || op->stopped_below_threshold) continue;
    // Left unrefined: only in a tracked frame, on the previous frame's template's lead, the
    // search pose reported as is and no runner-up searched.
    ++*left;
    EXPECT_TRUE(ea.tracking.tracked) << where;
    EXPECT_EQ(ea.tracking.prior_template, ha.template_name) << where;
    EXPECT_LT(op->score, ha.score - 3.0) << where;
    EXPECT_TRUE(SamePose(oa->pose, oa->lattice_pose)) << where;
    EXPECT_FALSE(oa->has_runner_up) << where;
    EXPECT_TRUE(ob->refined) << where;
    EXPECT_LT(ob->fit.fit, hb.fit.fit) << where << ": the template refined anyway fits worse";
    if (oa->stopped_below_threshold) {
      // Stopped: proved more than the margin behind; its optimum lies under the bound, the
      // pose it reports scores what it says and no more than the optimum.
      ++*stopped;
      EXPECT_LT(oa->score_upper_bound, ha.score - 3.0) << where;
      EXPECT_LE(op->score, oa->score_upper_bound + 1e-9) << where;
      EXPECT_LE(oa->score, op->score) << where;
      EXPECT_NEAR(ea.Humanoids().front().template_margin, ha.score - oa->score_upper_bound, 1e-9)
          << where;
    } else {
      EXPECT_EQ(oa->score, op->score) << where;
    }
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
  int left = 0, stopped = 0;
  StreamAll(steps, &chosen, &left, &stopped);
  for (const std::string& name : chosen) EXPECT_EQ(name, "standing");
  std::printf(
      "the other template was left unrefined in %d of %zu frames, its search stopped in "
      "%d\n",
      left, steps.size(), stopped);
  EXPECT_GE(left, 2);
  EXPECT_GE(stopped, 1);
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
  int left = 0, stopped = 0;
  StreamAll(steps, &chosen, &left, &stopped);
  ASSERT_EQ(chosen.size(), steps.size());
  EXPECT_EQ(chosen[0], "standing");
  EXPECT_EQ(chosen[1], "standing");
  for (size_t k = 2; k < chosen.size(); ++k) EXPECT_EQ(chosen[k], "right_arm_raised") << k;
  // Once the raised arm is the previous frame's template, standing is the one left behind.
  EXPECT_GE(left, 1);
}

// Estimates `frame` with `prior` by an estimator with `options` and by the same with the other
// templates' searches proving their optima (tracked_other_template_stops off); expects the prior
// template's candidate near `truth` refined, the other template proved more than the margin
// behind it, and every candidate the same in both (a stopped search's bound at or above the
// proved optimum). Returns the first estimate.
Estimate SameAsProving(const EstimatorOptions& options, const SimulatedFrame& frame,
                       const FramePrior& prior, const Pose2D& truth) {
  EstimatorOptions proving_options = options;
  proving_options.tracked_other_template_stops = false;
  const auto stopping = std::move(Estimator::Create(options, Templates()).value());
  const auto proving = std::move(Estimator::Create(proving_options, Templates()).value());
  const Intrinsics intrinsics = FrameSpec().intrinsics;
  const Estimate es = *stopping->EstimateDepth(frame.depth, intrinsics, &prior);
  const Estimate ep = *proving->EstimateDepth(frame.depth, intrinsics, &prior);
  const Candidate* lead = nullptr;
  for (const Candidate& c : es.candidates) {
    if (c.template_name == prior.template_name &&
        std::hypot(c.pose.x - truth.x, c.pose.y - truth.y) < 0.1) {
      lead = &c;
    }
  }
  EXPECT_NE(lead, nullptr);
  if (lead == nullptr) return es;
  EXPECT_TRUE(lead->refined);
  const std::string other_name =
      prior.template_name == "standing" ? "right_arm_raised" : "standing";
  // Far enough behind that its search stops behind the lead's score.
  const Candidate* other_proved = CandidateOf(ep, lead->cluster_index, other_name);
  EXPECT_NE(other_proved, nullptr);
  if (other_proved != nullptr) EXPECT_LT(other_proved->score, lead->score - 3.0);
  EXPECT_EQ(es.candidates.size(), ep.candidates.size());
  for (size_t i = 0; i < std::min(es.candidates.size(), ep.candidates.size()); ++i) {
    const Candidate& a = es.candidates[i];
    const Candidate& b = ep.candidates[i];
    const std::string what = a.template_name + " on cluster " + std::to_string(a.cluster_index);
    EXPECT_EQ(a.template_name, b.template_name) << what;
    EXPECT_EQ(a.refined, b.refined) << what;
    EXPECT_EQ(a.fit.fit, b.fit.fit) << what;
    if (a.cluster_index == lead->cluster_index && a.template_name == other_name &&
        a.stopped_below_threshold) {
      EXPECT_FALSE(b.stopped_below_threshold) << what;
      EXPECT_LE(b.score, a.score_upper_bound) << what;  // stopped there, proved here.
      continue;
    }
    EXPECT_EQ(a.score, b.score) << what;
    EXPECT_TRUE(SamePose(a.pose, b.pose)) << what;
    EXPECT_EQ(a.stopped_below_threshold, b.stopped_below_threshold) << what;
  }
  return es;
}

FramePrior PriorAt(const Pose2D& pose, double score) {
  FramePrior prior;
  prior.has_pose = true;
  prior.template_name = "standing";
  prior.pose = pose;
  prior.score = score;
  return prior;
}

// Where the previous frame's template does not pass on its cluster (here: no refined pose meets
// the fit asked), a search stopped behind it goes on down to the score threshold and its
// template is refined: every candidate is then what the searches that prove their optima give.
TEST(TrackedTemplatesTest, AStoppedSearchGoesOnWhereThePreviousTemplateFails) {
  EstimatorOptions strict = Options(3.0);
  strict.min_humanoid_fit = 100.0;
  const Pose2D truth{1.5, -0.1, DegToRad(-60.0)};
  const Estimate e =
      SameAsProving(strict, Frame("standing", truth, 7), PriorAt(truth, 65.0), truth);
  EXPECT_TRUE(e.Humanoids().empty());
  for (const Candidate& c : e.candidates) EXPECT_FALSE(c.stopped_below_threshold && c.refined);
}

// A frame whose held cluster reaches only the tracked threshold (here: the full one set above
// any score) is searched again down to it; the previous frame's template is then refined before
// the others are judged against it, and the far-behind one is left as the proving search leaves
// it.
TEST(TrackedTemplatesTest, AFrameSearchedAgainByTheTrackedThresholdJudgesTheOthersTheSame) {
  EstimatorOptions high = Options(3.0);
  high.score_threshold = 95.0;
  high.tracked_score_threshold = 40.0;
  const Pose2D truth{1.5, -0.1, DegToRad(-60.0)};
  const Estimate e = SameAsProving(high, Frame("standing", truth, 7), PriorAt(truth, 96.0), truth);
  ASSERT_EQ(e.Humanoids().size(), 1u);
  const Candidate& h = e.Humanoids().front().best;
  EXPECT_EQ(h.template_name, "standing");
  const Candidate* other = CandidateOf(e, h.cluster_index, "right_arm_raised");
  ASSERT_NE(other, nullptr);
  EXPECT_FALSE(other->refined);
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
