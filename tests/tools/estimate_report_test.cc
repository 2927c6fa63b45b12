// What `hpose estimate` prints when no humanoid passes: the nearest miss and which rule refused
// it (tools/estimate_report.h).
#include "tools/estimate_report.h"

#include <gtest/gtest.h>

#include <string>

#include "core/search/estimator.h"

namespace hpose::tools {
namespace {

// A frame whose only detection is a refined candidate 3.6 m away that is not a humanoid.
Estimate Miss(double score, double fit, int hits, double threshold, Refusal refused_by) {
  Candidate c;
  c.template_name = "standing";
  c.cluster_index = 6;
  c.pose = Pose2D{3.6, 0.0, 0.0};
  c.refined = true;
  c.fit.fit = fit;
  c.score = score;
  c.hits = hits;
  c.template_voxels = 1000;
  Detection d;
  d.best = c;
  d.score_threshold = threshold;
  d.refused_by = refused_by;
  Estimate e;
  e.detections.push_back(d);
  return e;
}

// The text after "humanoid  none found (best: ", up to the end of its line.
std::string Why(const Estimate& e, const EstimatorOptions& o) {
  const std::string text = EstimateToText(e, &o);
  const std::string head = "humanoid  none found (best: standing on cluster 6, 3.6 m away, ";
  const size_t at = text.find(head);
  if (at == std::string::npos) return "(no nearest miss in: " + text + ")";
  const size_t from = at + head.size();
  return text.substr(from, text.find('\n', from) - from);
}

TEST(EstimateReportTest, AFarClusterWithoutTheEvidenceSaysWhatItHasAndNeeds) {
  const EstimatorOptions o;  // far clusters from 2.5 m, under score 50, need evidence 0.08.
  // Passed the far score (40) and the fit (60), but 400 hits of 1000 at a fit of 75 are
  // 0.4 * 0.75^8 = 0.040 of the template.
  EXPECT_EQ(Why(Miss(45.6, 75.0, 400, 40.0, Refusal::kFarEvidence), o),
            "score 45.6 and a refined fit of 75.0, but a cluster 2.5 m away or more that scores "
            "under 50 needs evidence of 0.08 and this has 0.040: the share of the template it "
            "covers times (fit/100)^8)");
}

TEST(EstimateReportTest, EachRefusalNamesItsRule) {
  const EstimatorOptions o;
  EXPECT_EQ(Why(Miss(52.0, 41.5, 500, 50.0, Refusal::kFit), o),
            "score 52.0 but a refined fit of 41.5, below the fit threshold 60: --min-fit)");
  EXPECT_EQ(Why(Miss(38.0, 90.0, 400, 40.0, Refusal::kScore), o), "score 38.0, below 40)");
  // 5 hits of 1000 at a fit of 90: 0.005 * 0.9^8 = 0.002 of the template.
  EXPECT_EQ(Why(Miss(55.0, 90.0, 5, 50.0, Refusal::kEvidence), o),
            "score 55.0 and a refined fit of 90.0, but evidence of 0.002 (the share of the "
            "template it covers times (fit/100)^8), below 0.01: --min-evidence)");
  Estimate lower = Miss(55.0, 80.0, 120, 50.0, Refusal::kOffFloorCoverage);
  lower.detections[0].best.height_offset_m = -0.016;
  EXPECT_EQ(Why(lower, o),
            "score 55.0 and a refined fit of 80.0 with the template 16 mm below the floor, but "
            "covering 0.12 of the template, under the 0.15 a body off the floor must cover: "
            "search.height_offset_min_coverage)");
  Estimate stopped = Miss(0.0, 0.0, 0, 50.0, Refusal::kScore);
  stopped.detections[0].best.stopped_below_threshold = true;
  stopped.detections[0].best.score_upper_bound = 31.24;
  EXPECT_EQ(Why(stopped, o), "proved below score 50: at most 31.2)");
}

// A cluster refused for its fit or evidence whose template's free limbs the frame contradicted
// (Candidate::free_limbs_moved) may be the robot in another posture: the report says so, and
// only then.
TEST(EstimateReportTest, LimbsHeldOtherwisePointToATemplateOfThePosture) {
  const EstimatorOptions o;
  const std::string hint = "contradicts the template's free limbs";
  for (const Refusal r : {Refusal::kFit, Refusal::kEvidence, Refusal::kFarEvidence}) {
    Estimate moved = Miss(55.0, 58.0, 400, 50.0, r);
    moved.detections[0].best.free_limbs_moved = true;
    EXPECT_NE(EstimateToText(moved, &o).find(hint), std::string::npos) << static_cast<int>(r);
    EXPECT_EQ(EstimateToText(Miss(55.0, 58.0, 400, 50.0, r), &o).find(hint), std::string::npos)
        << static_cast<int>(r);
  }
  Estimate low_score = Miss(38.0, 90.0, 400, 50.0, Refusal::kScore);
  low_score.detections[0].best.free_limbs_moved = true;
  EXPECT_EQ(EstimateToText(low_score, &o).find(hint), std::string::npos);
}

TEST(EstimateReportTest, AFarClusterRefusedByItsScoreGetsTheFarHint) {
  const EstimatorOptions o;
  const std::string hint = "far humanoids score less";
  EXPECT_NE(EstimateToText(Miss(38.0, 90.0, 400, 40.0, Refusal::kScore), &o).find(hint),
            std::string::npos);
  EXPECT_EQ(EstimateToText(Miss(52.0, 41.5, 500, 50.0, Refusal::kFit), &o).find(hint),
            std::string::npos);
}

// A frame searched again off the floor says how many heights its search time went to.
TEST(EstimateReportTest, TimingsSayHowManyHeightsWereSearched) {
  const EstimatorOptions o;
  Estimate e = Miss(38.0, 90.0, 400, 40.0, Refusal::kScore);
  EXPECT_EQ(EstimateToText(e, &o).find("heights"), std::string::npos);
  e.height_passes = 5;
  EXPECT_NE(EstimateToText(e, &o).find(" ms at 5 heights (--height-offset-voxels), total "),
            std::string::npos)
      << EstimateToText(e, &o);
}

// The margin over the second template is named in the points it is in
// (Detection::template_margin_kind): fit points where both templates were refined, else score
// points, at least that many where the second's search stopped.
TEST(EstimateReportTest, TheTemplateMarginSaysWhichPointsItIsIn) {
  const EstimatorOptions o;
  Estimate e = Miss(66.0, 97.0, 800, 50.0, Refusal::kNone);
  Detection& d = e.detections[0];
  d.is_humanoid = true;
  d.second_template = "right_arm_raised";
  d.template_margin = 4.5;
  d.template_margin_kind = MarginKind::kFit;
  EXPECT_NE(EstimateToText(e, &o).find("right_arm_raised fits 4.5 lower\n"), std::string::npos)
      << EstimateToText(e, &o);
  d.template_margin_kind = MarginKind::kScore;
  EXPECT_NE(EstimateToText(e, &o).find("right_arm_raised scored 4.5 lower\n"), std::string::npos)
      << EstimateToText(e, &o);
  d.template_margin_kind = MarginKind::kScoreAtLeast;
  EXPECT_NE(EstimateToText(e, &o).find("right_arm_raised scored at least 4.5 lower\n"),
            std::string::npos)
      << EstimateToText(e, &o);
}

// A pose whose template the image's edges cut says how much of it the view holds, a humanoid's
// and a nearest miss's alike; one in view whole says nothing of it.
TEST(EstimateReportTest, APartlyInViewPoseSaysHowMuch) {
  const EstimatorOptions o;
  const std::string lines =
      "          partly in view: 42% of the template's surface facing the sensor lies within the "
      "view,\n          the rest beyond the image's edges: the fit rests on the part in view\n";
  Estimate e = Miss(66.0, 97.0, 800, 50.0, Refusal::kNone);
  e.detections[0].is_humanoid = true;
  e.detections[0].best.fit.in_view = 0.42;
  EXPECT_NE(EstimateToText(e, &o).find(lines), std::string::npos) << EstimateToText(e, &o);
  Estimate miss = Miss(55.0, 90.0, 5, 50.0, Refusal::kEvidence);
  miss.detections[0].best.fit.in_view = 0.42;
  EXPECT_NE(EstimateToText(miss, &o).find(lines), std::string::npos) << EstimateToText(miss, &o);
  e.detections[0].best.fit.in_view = 0.97;
  miss.detections[0].best.fit.in_view = 0.97;
  EXPECT_EQ(EstimateToText(e, &o).find("partly in view"), std::string::npos);
  EXPECT_EQ(EstimateToText(miss, &o).find("partly in view"), std::string::npos);
}

}  // namespace
}  // namespace hpose::tools
