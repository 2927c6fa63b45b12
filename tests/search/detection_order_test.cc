// Across clusters, the humanoid with the most evidence comes first: covered voxels weighted by
// the refined fit, not the search score (the share of a cluster's own voxels covered, which a
// small object inside the template's outline reaches more easily than the robot does).
#include "core/search/detection_order.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/search/estimator.h"
#include "core/sim/frame_simulator.h"
#include "core/sim/humanoid_model.h"

namespace hpose {
namespace {

Detection Made(double score, double fit, int hits, bool humanoid = true, bool refined = true) {
  Detection d;
  d.best.score = score;
  d.best.fit.fit = fit;
  d.best.hits = hits;
  d.best.refined = refined;
  d.is_humanoid = humanoid;
  return d;
}

TEST(DetectionOrderTest, EvidenceIsHitsTimesTheFitToTheEighth) {
  const Detection d = Made(70.0, 90.0, 200);
  EXPECT_NEAR(HumanoidEvidence(d.best), 200 * std::pow(0.9, 8), 1e-9);
  EXPECT_EQ(HumanoidEvidence(Made(70.0, 90.0, 200, true, false).best), 0.0);
  EXPECT_GT(HumanoidEvidence(Made(50.0, 90.0, 201).best), HumanoidEvidence(d.best));
  EXPECT_GT(HumanoidEvidence(Made(50.0, 91.0, 200).best), HumanoidEvidence(d.best));
}

TEST(DetectionOrderTest, TheRobotGoesBeforeClutterThatOutscoresIt) {
  // Scores and fits as estimates of simulated frames gave them (the sliver's covered voxels
  // assumed, 60): a thin box inside the template's outline (higher score, fewer voxels, worse
  // fit), a sliver of a box cut by the image's top (fits perfectly, few voxels), a larger box
  // (more voxels, the template seen through around it).
  const Detection robot = Made(73.7, 89.7, 639);
  EXPECT_TRUE(DetectionBefore(robot, Made(88.0, 68.8, 176)));
  EXPECT_FALSE(DetectionBefore(Made(88.0, 68.8, 176), robot));
  const Detection near_robot = Made(70.5, 90.9, 535);
  EXPECT_TRUE(DetectionBefore(near_robot, Made(88.8, 100.0, 60)));
  const Detection partly_seen = Made(71.1, 91.6, 170);
  EXPECT_TRUE(DetectionBefore(partly_seen, Made(72.7, 78.0, 276)));
}

TEST(DetectionOrderTest, HumanoidsFirstThenRefinedThenByScore) {
  EXPECT_TRUE(DetectionBefore(Made(51.0, 61.0, 10), Made(99.0, 59.0, 900, false)));
  EXPECT_FALSE(DetectionBefore(Made(99.0, 59.0, 900, false), Made(51.0, 61.0, 10)));
  // Refined humanoids before unrefined ones; unrefined ones and non-humanoids by score.
  EXPECT_TRUE(DetectionBefore(Made(51.0, 61.0, 10), Made(90.0, 0.0, 900, true, false)));
  EXPECT_TRUE(DetectionBefore(Made(80.0, 0.0, 10, true, false), Made(70.0, 0.0, 900, true, false)));
  EXPECT_TRUE(DetectionBefore(Made(80.0, 50.0, 10, false), Made(70.0, 99.0, 900, false)));
  // Equal evidence: by score. Irreflexive.
  EXPECT_TRUE(DetectionBefore(Made(60.0, 90.0, 100), Made(55.0, 90.0, 100)));
  const Detection d = Made(60.0, 90.0, 100);
  EXPECT_FALSE(DetectionBefore(d, d));
}

TEST(DetectionOrderTest, SortingAnyPermutationGivesOneOrder) {
  std::vector<Detection> ds = {Made(73.7, 89.7, 639),
                               Made(88.0, 68.8, 176),
                               Made(88.8, 100.0, 60),
                               Made(60.0, 90.0, 100),
                               Made(55.0, 90.0, 100),
                               Made(80.0, 0.0, 10, true, false),
                               Made(70.0, 0.0, 900, true, false),
                               Made(95.0, 40.0, 700, false),
                               Made(65.0, 99.0, 50, false)};
  std::vector<int> order(ds.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  const auto sorted_scores = [&](std::vector<int> perm) {
    std::vector<Detection> v;
    for (int i : perm) v.push_back(ds[i]);
    std::stable_sort(v.begin(), v.end(), DetectionBefore);
    std::vector<double> out;
    for (const Detection& d : v) out.push_back(d.best.score);
    return out;
  };
  const std::vector<double> first = sorted_scores(order);
  // Evidence 268, 60, 43.0 (twice: by score), 8.9; then unrefined humanoids, others by score.
  EXPECT_EQ(first, (std::vector<double>{73.7, 88.8, 60.0, 55.0, 88.0, 80.0, 70.0, 95.0, 65.0}));
  int permutations = 0;
  do {
    if (++permutations % 97 != 0) continue;  // a spread of the 362 880.
    EXPECT_EQ(sorted_scores(order), first);
  } while (std::next_permutation(order.begin(), order.end()));
}

VoxelTemplate BodyTemplate(const std::string& preset, const std::string& body) {
  const HumanoidModel model =
      *HumanoidModel::FromPreset(preset, *HumanoidDimensions::Variant(body));
  return *MakeTemplateFromPoints(*model.SampleSurface(0.004), preset, 0.016, preset, "test");
}

// Simulated frames in which clutter outscores the humanoid and passes both thresholds: the
// humanoid still comes first. Each frame has such clutter with gcc's arithmetic and clang's.
TEST(DetectionOrderTest, OnFramesWhereClutterOutscoresTheHumanoidItComesFirst) {
  struct Scene {
    const char* body;
    const char* preset;
    Pose2D pose;
    double height_m, pitch_deg;
    int clutter;
    std::uint64_t seed;
  };
  const Scene scenes[] = {
      {"long_legs", "right_arm_raised", {0.9809, -0.1770, -0.0732}, 0.6285, 29.233, 10, 1063},
      {"nao",
       "right_arm_raised",
       {2.9257592234000995, 0.50897876747303616, -2.7546043390373645},
       0.54823416997194618,
       23.751822921654341,
       7,
       2201},
  };
  for (const Scene& s : scenes) {
    SCOPED_TRACE(std::string(s.body) + " seed " + std::to_string(s.seed));
    FrameSpec spec;
    spec.body = s.body;
    spec.preset = s.preset;
    spec.humanoid_pose = s.pose;
    spec.sensor_height_m = s.height_m;
    spec.sensor_pitch_rad = DegToRad(s.pitch_deg);
    spec.clutter = s.clutter;
    spec.seed = s.seed;
    spec.noise_correlated_share = 0.9;
    const SimulatedFrame frame = *SimulateFrame(spec);
    const auto estimator = std::move(
        Estimator::Create(DefaultEstimatorOptions(), {BodyTemplate("standing", s.body),
                                                      BodyTemplate("right_arm_raised", s.body)})
            .value());
    const Estimate e = *estimator->EstimateDepth(frame.depth, spec.intrinsics);
    const auto near_truth = [&](const Detection& d) {
      return std::hypot(d.best.pose.x - s.pose.x, d.best.pose.y - s.pose.y) < 0.05;
    };
    const std::vector<Detection> humanoids = e.Humanoids();
    ASSERT_GE(humanoids.size(), 2u);
    const auto top_score = std::max_element(
        humanoids.begin(), humanoids.end(),
        [](const Detection& a, const Detection& b) { return a.best.score < b.best.score; });
    EXPECT_FALSE(near_truth(*top_score)) << "the frame no longer tests the order";
    EXPECT_TRUE(near_truth(humanoids.front()));
    EXPECT_TRUE(near_truth(e.detections.front()));
    EXPECT_TRUE(std::is_sorted(e.detections.begin(), e.detections.end(), DetectionBefore));
  }
}

}  // namespace
}  // namespace hpose
