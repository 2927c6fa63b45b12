#include "core/templates/voxel_template.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace hpose {
namespace {

TEST(MakeTemplateFromPointsTest, VoxelisesToUniqueCentres) {
  // Two points in one 16 mm cell, one in the next cell up.
  const std::vector<Eigen::Vector3f> pts = {
      {0.001f, 0.001f, 0.001f}, {0.015f, 0.010f, 0.002f}, {0.001f, 0.001f, 0.020f}};
  Result<VoxelTemplate> t = MakeTemplateFromPoints(pts, "box", 0.016, "", "test");
  ASSERT_TRUE(t.ok()) << t.error().ToString();
  ASSERT_EQ(t->voxels.size(), 2u);
  EXPECT_NEAR(t->voxels[0].x(), 0.008, 1e-6);
  EXPECT_NEAR(t->voxels[1].z(), 0.024, 1e-6);
  EXPECT_EQ(t->variant, "box");
  EXPECT_NEAR(t->Height(), 0.032, 1e-6);
}

TEST(MakeTemplateFromPointsTest, NegativeCoordinatesFloorCorrectly) {
  const std::vector<Eigen::Vector3f> pts = {{-0.001f, -0.017f, 0.0f}};
  Result<VoxelTemplate> t = MakeTemplateFromPoints(pts, "n", 0.016);
  ASSERT_TRUE(t.ok());
  EXPECT_NEAR(t->voxels[0].x(), -0.008, 1e-6);
  EXPECT_NEAR(t->voxels[0].y(), -0.024, 1e-6);
}

TEST(MakeTemplateFromPointsTest, RejectsBadInput) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(MakeTemplateFromPoints({{nan, 0, 0}}, "x", 0.016).error().code,
            ErrorCode::kInvalidArgument);
  EXPECT_EQ(MakeTemplateFromPoints({}, "x", 0.016).error().code, ErrorCode::kInvalidArgument);
  EXPECT_EQ(MakeTemplateFromPoints({{0, 0, 0}}, "bad name", 0.016).error().code,
            ErrorCode::kInvalidArgument);
  EXPECT_EQ(MakeTemplateFromPoints({{0, 0, 0}}, "x", 0.0).error().code,
            ErrorCode::kInvalidArgument);
  // Millimetres passed as metres are caught, not silently voxelised.
  EXPECT_EQ(MakeTemplateFromPoints({{580.0f, 0, 0}}, "x", 0.016).error().code,
            ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace hpose
