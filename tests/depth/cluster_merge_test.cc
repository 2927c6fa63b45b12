#include "core/depth/cluster_merge.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace hpose {
namespace {

// A vertical slab of points facing the sensor (at the ground origin, looking along +x).
Cluster Slab(float x, float y_lo, float y_hi, float z_hi) {
  Cluster c;
  for (float y = y_lo; y <= y_hi; y += 0.01f)
    for (float z = 0.05f; z <= z_hi; z += 0.01f) c.points.emplace_back(x, y, z);
  return c;
}

TEST(MergePiecesAlongSightTest, MergesAnArmInFrontOfItsBody) {
  std::vector<Cluster> clusters = {Slab(1.0f, -0.07f, 0.07f, 0.58f),    // torso and head.
                                   Slab(0.96f, -0.03f, 0.02f, 0.46f)};  // arm, 4 cm nearer.
  MergePiecesAlongSight(0.5, 0.08, &clusters);
  ASSERT_EQ(clusters.size(), 1u);
  EXPECT_GT(clusters[0].points.size(), 800u);
}

TEST(MergePiecesAlongSightTest, KeepsObjectsSideBySideOrOneBehindAnother) {
  std::vector<Cluster> side_by_side = {Slab(2.0f, -0.4f, -0.01f, 1.7f),
                                       Slab(2.0f, 0.01f, 0.4f, 1.7f)};
  MergePiecesAlongSight(0.5, 0.08, &side_by_side);
  EXPECT_EQ(side_by_side.size(), 2u);
  std::vector<Cluster> behind = {Slab(2.0f, -0.2f, 0.2f, 1.7f), Slab(2.3f, -0.2f, 0.2f, 1.7f)};
  MergePiecesAlongSight(0.5, 0.08, &behind);
  EXPECT_EQ(behind.size(), 2u);
  // Disabled: nothing merges.
  std::vector<Cluster> arm = {Slab(1.0f, -0.07f, 0.07f, 0.58f), Slab(0.96f, -0.03f, 0.02f, 0.46f)};
  MergePiecesAlongSight(0.0, 0.08, &arm);
  EXPECT_EQ(arm.size(), 2u);
}

// The extent from the extreme points equals the one from every point's atan2 and hypot (in
// float, to a float rounding), on random clusters all around the sensor: across the -x axis, where
// atan2 jumps from pi to -pi, on the axes with signed zeros, and at the origin.
TEST(SightExtentTest, EqualsTheExtentOfEveryPointsBearingAndRange) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> angle(-3.2f, 3.2f), spread(0.0f, 1.0f), r(0.0f, 4.0f);
  const float specials[][2] = {{1.0f, 0.0f},   {1.0f, -0.0f}, {-1.0f, 0.0f}, {-1.0f, -0.0f},
                               {0.0f, 1.0f},   {0.0f, -1.0f}, {0.0f, 0.0f},  {-0.0f, 0.0f},
                               {-0.0f, -0.0f}, {0.0f, -0.0f}};
  for (int trial = 0; trial < 300; ++trial) {
    Cluster c;
    const float centre = angle(rng), width = spread(rng) * spread(rng) * 3.0f;
    const int n = 1 + trial % 40;
    for (int i = 0; i < n; ++i) {
      const float a = centre + width * (spread(rng) - 0.5f), d = r(rng);
      c.points.emplace_back(d * std::cos(a), d * std::sin(a), 0.5f);
    }
    if (trial % 3 == 0) {
      const auto& s = specials[(trial / 3) % 10];
      c.points.emplace_back(s[0], s[1], 0.5f);
    }
    double b_lo = 1e300, b_hi = -1e300, r_lo = 1e300, r_hi = -1e300;
    for (const Eigen::Vector3f& p : c.points) {
      const double b = std::atan2(p.y(), p.x()), range = std::hypot(p.x(), p.y());
      b_lo = std::min(b_lo, b);
      b_hi = std::max(b_hi, b);
      r_lo = std::min(r_lo, range);
      r_hi = std::max(r_hi, range);
    }
    const SightExtent e = SightExtentOf(c);
    const double tol = 3e-7;  // about a float rounding at pi.
    ASSERT_NEAR(e.bearing_lo, b_lo, tol) << "trial " << trial;
    ASSERT_NEAR(e.bearing_hi, b_hi, tol) << "trial " << trial;
    ASSERT_NEAR(e.range_lo, r_lo, tol * std::max(1.0, r_lo)) << "trial " << trial;
    ASSERT_NEAR(e.range_hi, r_hi, tol * std::max(1.0, r_hi)) << "trial " << trial;
    // Signed zeros on the -x axis and at the origin decide between pi and -pi exactly.
    if (b_lo == -M_PI || b_hi == M_PI) {
      EXPECT_EQ(e.bearing_lo == -M_PI, b_lo == -M_PI);
      EXPECT_EQ(e.bearing_hi == M_PI, b_hi == M_PI);
    }
  }
}

}  // namespace
}  // namespace hpose
