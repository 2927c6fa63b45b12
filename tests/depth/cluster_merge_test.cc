#include "core/depth/cluster_merge.h"

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

}  // namespace
}  // namespace hpose
