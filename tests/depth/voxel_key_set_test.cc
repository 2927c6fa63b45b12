#include "core/depth/voxel_key_set.h"

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace hpose {
namespace {

// Whether some point of `points` lies in the same cube of side `leaf` as `p`, by looking at all.
bool SameCubeAsAny(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& p,
                   float leaf) {
  const Eigen::Vector3f cell = (p / leaf).array().floor();
  for (const Eigen::Vector3f& q : points) {
    if (((q / leaf).array().floor() == cell.array()).all()) return true;
  }
  return false;
}

TEST(VoxelKeySetTest, AnswersAsLookingAtEveryPointDoes) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> coord(-1.5f, 1.5f);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 400; ++i) points.emplace_back(coord(rng), coord(rng), 0.3f * coord(rng));
  VoxelKeySet set;
  set.Build(points, 0.06f);
  EXPECT_GT(set.size(), 300u);  // a few points share a cube.
  EXPECT_LE(set.size(), points.size());
  int inside = 0;
  for (const Eigen::Vector3f& p : points) EXPECT_TRUE(set.Contains(p));
  for (int i = 0; i < 20000; ++i) {
    const Eigen::Vector3f p(coord(rng), coord(rng), 0.3f * coord(rng));
    const bool expected = SameCubeAsAny(points, p, 0.06f);
    ASSERT_EQ(set.Contains(p), expected) << p.transpose();
    inside += expected ? 1 : 0;
  }
  EXPECT_GT(inside, 100);  // both answers were asked for.
  EXPECT_LT(inside, 19900);
}

TEST(VoxelKeySetTest, EmptyAndRebuiltSetsForgetWhatTheyHeld) {
  VoxelKeySet set;
  EXPECT_FALSE(set.Contains(Eigen::Vector3f::Zero()));
  set.Build({Eigen::Vector3f(0.01f, 0.01f, 0.01f)}, 0.03f);
  EXPECT_TRUE(set.Contains(Eigen::Vector3f(0.02f, 0.0f, 0.029f)));
  EXPECT_FALSE(set.Contains(Eigen::Vector3f(0.02f, 0.0f, 0.031f)));
  EXPECT_FALSE(set.Contains(Eigen::Vector3f(-0.001f, 0.0f, 0.01f)));
  set.Build({}, 0.03f);
  EXPECT_EQ(set.size(), 0u);
  EXPECT_FALSE(set.Contains(Eigen::Vector3f(0.01f, 0.01f, 0.01f)));
}

}  // namespace
}  // namespace hpose
