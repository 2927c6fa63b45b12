#include "core/templates/voxel_template.h"

#include <cmath>
#include <limits>
#include <string>
#include <vector>

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

// A template voxelised again at a coarser edge: from its surface points (so the same as made
// from them at that edge), its names and source kept whatever they are; from its voxel centres
// when it has no surface; never at a finer edge.
TEST(VoxeliseAgainTest, CoarserFromTheSurfaceNeverFiner) {
  std::vector<Eigen::Vector3f> pts;
  for (int i = 0; i < 200; ++i) {
    const float a = 0.0314f * static_cast<float>(i);
    pts.emplace_back(0.1f * std::cos(a), 0.05f * std::sin(a), 0.003f * static_cast<float>(i));
  }
  Result<VoxelTemplate> t = MakeTemplateFromPoints(pts, "ring", 0.016, "spiral", "test");
  ASSERT_TRUE(t.ok()) << t.error().ToString();
  t->name = "loaded name";  // as a sidecar may give it; not one MakeTemplateFromPoints takes.
  Result<VoxelTemplate> again = VoxeliseAgain(*t, 0.028);
  ASSERT_TRUE(again.ok()) << again.error().ToString();
  const VoxelTemplate direct = *MakeTemplateFromPoints(t->surface, "ring", 0.028, "spiral", "test");
  EXPECT_EQ(again->name, "loaded name");
  EXPECT_EQ(again->variant, "spiral");
  EXPECT_EQ(again->source, "test");
  EXPECT_EQ(again->resolution_m, 0.028);
  EXPECT_EQ(again->voxels, direct.voxels);
  EXPECT_EQ(again->surface, direct.surface);
  EXPECT_LT(again->voxels.size(), t->voxels.size());
  EXPECT_NEAR(again->Height(), std::ceil(t->Height() / 0.028 - 1e-6) * 0.028, 0.0281);

  VoxelTemplate bare = *t;
  bare.surface.clear();
  Result<VoxelTemplate> from_centres = VoxeliseAgain(bare, 0.032);
  ASSERT_TRUE(from_centres.ok());
  EXPECT_EQ(from_centres->voxels, MakeTemplateFromPoints(bare.voxels, "c", 0.032)->voxels);

  Result<VoxelTemplate> finer = VoxeliseAgain(*t, 0.010);
  ASSERT_FALSE(finer.ok());
  EXPECT_EQ(finer.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(finer.error().message.find("16.0 mm"), std::string::npos) << finer.error().message;
  EXPECT_TRUE(VoxeliseAgain(*t, 0.016).ok());
}

TEST(MarkSurfaceCellsTest, MarksTheCellsThePartTouches) {
  // Two cells of 8 mm: the part's samples lie in the second only.
  const std::vector<Eigen::Vector3f> surface = {{0.004f, 0.004f, 0.004f}, {0.012f, 0.004f, 0.004f}};
  const std::vector<Eigen::Vector3f> part = {{0.009f, 0.001f, 0.007f}, {0.015f, 0.0f, 0.0f}};
  EXPECT_EQ(MarkSurfaceCells(surface, part, 0.008), (std::vector<std::uint8_t>{0, 1}));
  EXPECT_EQ(MarkSurfaceCells(surface, {}, 0.008), (std::vector<std::uint8_t>{0, 0}));
}

TEST(VoxeliseAgainTest, FreeLimbMarksFollowTheCoarserSurface) {
  std::vector<Eigen::Vector3f> pts;
  for (int x = 0; x < 40; ++x)
    for (int z = 0; z < 60; ++z) pts.emplace_back(0.004f * x, 0.0f, 0.004f * z + 0.001f);
  VoxelTemplate t = *MakeTemplateFromPoints(pts, "wall", 0.016);
  // The upper part (z above 0.16 m) is a free limb.
  for (const Eigen::Vector3f& p : t.surface) t.free_limb.push_back(p.z() > 0.16f);
  Result<VoxelTemplate> coarse = VoxeliseAgain(t, 0.032);
  ASSERT_TRUE(coarse.ok()) << coarse.error().message;
  ASSERT_EQ(coarse->free_limb.size(), coarse->surface.size());
  for (size_t i = 0; i < coarse->surface.size(); ++i) {
    // Cells of 16 mm: those wholly above 0.176 m are marked, those wholly below 0.16 m are not.
    const float z = coarse->surface[i].z();
    if (z > 0.18f) EXPECT_EQ(coarse->free_limb[i], 1) << z;
    if (z < 0.15f) EXPECT_EQ(coarse->free_limb[i], 0) << z;
  }
}

}  // namespace
}  // namespace hpose
