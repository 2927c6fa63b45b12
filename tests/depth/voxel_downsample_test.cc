#include "core/depth/voxel_downsample.h"

#include <gtest/gtest.h>

namespace hpose {
namespace {

TEST(VoxelDownsampleTest, AveragesPointsPerVoxelAndMapsEveryPoint) {
  const std::vector<Eigen::Vector3f> points = {
      {0.01f, 0.01f, 0.01f}, {0.03f, 0.05f, 0.07f},  // voxel (0, 0, 0) at 0.1 m.
      {0.15f, 0.0f, 0.0f},                           // voxel (1, 0, 0).
      {-0.05f, 0.0f, 0.0f},                          // voxel (-1, 0, 0): floor, not truncation.
      {0.02f, 0.03f, 0.02f},                         // back to voxel (0, 0, 0).
  };
  std::vector<Eigen::Vector3f> centroids;
  std::vector<int> owner;
  VoxelDownsample(points, 0.1f, &centroids, &owner);
  ASSERT_EQ(centroids.size(), 3u);
  ASSERT_EQ(owner.size(), points.size());
  EXPECT_EQ(owner[0], 0);
  EXPECT_EQ(owner[1], 0);
  EXPECT_EQ(owner[4], 0);
  EXPECT_EQ(owner[2], 1);
  EXPECT_EQ(owner[3], 2);
  EXPECT_NEAR(centroids[0].x(), (0.01f + 0.03f + 0.02f) / 3, 1e-6);
  EXPECT_NEAR(centroids[0].y(), (0.01f + 0.05f + 0.03f) / 3, 1e-6);
  EXPECT_NEAR(centroids[0].z(), (0.01f + 0.07f + 0.02f) / 3, 1e-6);
  EXPECT_NEAR(centroids[2].x(), -0.05f, 1e-6);
}

TEST(VoxelDownsampleTest, HandlesLargeExtentsAndEmptyInput) {
  std::vector<Eigen::Vector3f> centroids = {{1, 2, 3}};
  VoxelDownsample({}, 0.01f, &centroids);
  EXPECT_TRUE(centroids.empty());
  // 1 km apart at 1 mm leaf: pcl::VoxelGrid would overflow its index here.
  VoxelDownsample({{0, 0, 0}, {1000, -1000, 500}}, 0.001f, &centroids);
  EXPECT_EQ(centroids.size(), 2u);
}

}  // namespace
}  // namespace hpose
