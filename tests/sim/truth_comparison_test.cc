// Estimates against a simulation's truth: frames found by file name, errors summed up.
#include "core/sim/truth_comparison.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/common/pose2d.h"
#include "core/common/quantile.h"

namespace hpose {
namespace {

TEST(TruthComparisonTest, FramesAreFoundByTheLastPartOfTheirPath) {
  SimTruth truth;
  truth.frames.resize(2);
  truth.frames[0].depth_file = "depth_000.png";
  truth.frames[0].cloud_file = "cloud_000.pcd";
  truth.frames[1].depth_file = "depth_001.png";
  EXPECT_EQ(FindFrameTruth(truth, "walk/depth_001.png"), &truth.frames[1]);
  EXPECT_EQ(FindFrameTruth(truth, "depth_000.png"), &truth.frames[0]);
  EXPECT_EQ(FindFrameTruth(truth, "/data/walk/cloud_000.pcd"), &truth.frames[0]);
  EXPECT_EQ(FindFrameTruth(truth, "walk/depth_002.png"), nullptr);
  EXPECT_EQ(FindFrameTruth(truth, "walk/"), nullptr);
  EXPECT_EQ(FindFrameTruth(truth, ""), nullptr);  // frame 1's empty cloud name is no match.
}

TEST(TruthComparisonTest, ErrorsAreSummedOverTheFramesFound) {
  TruthComparer comparer;
  const Pose2D truth{2.0, 0.5, DegToRad(179.0)};
  // 20 frames found 1..20 mm off along y, headings across the +-180 degree seam: 2 deg off.
  for (int i = 1; i <= 20; ++i) {
    comparer.Add(truth, {Pose2D{2.0, 0.5 + i * 1e-3, DegToRad(-179.0)}});
  }
  comparer.Add(truth, {});                                   // not found.
  comparer.Add(truth, {Pose2D{2.0, 0.5, DegToRad(-5.0)}});   // turned about: 176 deg.
  comparer.Add(truth, {Pose2D{2.3, 0.5, DegToRad(179.0)}});  // 0.3 m off.
  const TruthComparison s = comparer.Summary();
  EXPECT_EQ(s.frames, 23);
  EXPECT_EQ(s.found, 22);
  EXPECT_EQ(s.within_5deg_10cm, 20);
  EXPECT_EQ(s.turned_about, 1);
  EXPECT_NEAR(s.position_median_m, 0.010, 1e-9);  // 22 values: 0, 1..20 mm, 300 mm.
  EXPECT_NEAR(s.position_p95_m, 0.020, 1e-9);
  EXPECT_NEAR(s.position_max_m, 0.3, 1e-9);
  EXPECT_NEAR(RadToDeg(s.heading_median_rad), 2.0, 1e-9);
  EXPECT_NEAR(RadToDeg(s.heading_max_rad), 176.0, 1e-9);
  const std::string line = DescribeTruthComparison(s);
  EXPECT_NE(line.find("humanoid found in 22 of 23 frame(s), 20 within 5 deg and 0.1 m, 1 turned "
                      "about"),
            std::string::npos)
      << line;
  EXPECT_NE(line.find("position error median 10.0 mm, p95 20.0, max 300.0; heading error median "
                      "2.00 deg"),
            std::string::npos)
      << line;
}

TEST(TruthComparisonTest, OfSeveralHumanoidsTheNearestTheTruthIsCompared) {
  TruthComparer comparer;
  const Pose2D truth{2.0, 0.5, 0.0};
  // A second robot 1 m away facing the other way, listed first, then the robot 2 cm off.
  comparer.Add(truth, {Pose2D{2.0, -0.5, kPi}, Pose2D{2.02, 0.5, DegToRad(1.0)}});
  comparer.Add(truth, {Pose2D{2.0, 0.48, DegToRad(-2.0)}, Pose2D{3.0, 0.5, kPi}});
  const TruthComparison s = comparer.Summary();
  EXPECT_EQ(s.found, 2);
  EXPECT_EQ(s.within_5deg_10cm, 2);
  EXPECT_EQ(s.turned_about, 0);
  EXPECT_NEAR(s.position_max_m, 0.02, 1e-9);
  EXPECT_NEAR(RadToDeg(s.heading_max_rad), 2.0, 1e-9);
}

TEST(TruthComparisonTest, NothingFoundHasNoErrors) {
  TruthComparer comparer;
  comparer.Add(Pose2D{1.0, 0.0, 0.0}, {});
  const TruthComparison s = comparer.Summary();
  EXPECT_EQ(s.frames, 1);
  EXPECT_EQ(s.found, 0);
  EXPECT_EQ(s.position_max_m, 0.0);
  EXPECT_EQ(s.heading_max_rad, 0.0);
  // No errors are said of nothing found.
  EXPECT_EQ(DescribeTruthComparison(s),
            "humanoid found in 0 of 1 frame(s), 0 within 5 deg and 0.1 m, 0 turned about (over "
            "150 deg off)");
}

TEST(QuantileTest, NearestRank) {
  EXPECT_EQ(Quantile({}, 0.5), 0.0);
  EXPECT_EQ(Quantile({3.0, 1.0, 2.0}, 0.5), 2.0);
  EXPECT_EQ(Quantile({4.0, 1.0, 3.0, 2.0}, 0.5), 2.0);
  EXPECT_EQ(Quantile({4.0, 1.0, 3.0, 2.0}, 0.0), 1.0);
  EXPECT_EQ(Quantile({4.0, 1.0, 3.0, 2.0}, 1.0), 4.0);
  EXPECT_EQ(Quantile({4.0, 1.0, 3.0, 2.0}, 0.99), 4.0);
  EXPECT_EQ(QuantileOfSorted({1.0, 2.0, 3.0, 4.0}, 0.75), 3.0);
  EXPECT_EQ(QuantileOfSorted({}, 1.0), 0.0);
}

}  // namespace
}  // namespace hpose
