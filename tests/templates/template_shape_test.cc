#include "core/templates/template_shape.h"

#include <gtest/gtest.h>

namespace hpose {
namespace {

constexpr double kRes = 0.02;

Eigen::Vector3f Centre(int ix, int iy, int iz) {
  return Eigen::Vector3f((ix + 0.5f) * kRes, (iy + 0.5f) * kRes, (iz + 0.5f) * kRes);
}

// A solid block of voxels x in [-3, 3), y in [-4, 4), z in [0, 10): symmetric every way.
VoxelTemplate Block() {
  VoxelTemplate t;
  t.name = "block";
  t.resolution_m = kRes;
  for (int z = 0; z < 10; ++z)
    for (int y = -4; y < 4; ++y)
      for (int x = -3; x < 3; ++x) t.voxels.push_back(Centre(x, y, z));
  return t;
}

TEST(TemplateShapeTest, ViewsMapVoxelsToTheViewersImage) {
  VoxelTemplate t;
  t.resolution_m = kRes;
  t.voxels = {Centre(2, 1, 0)};
  const TemplateView front = ViewTemplate(t, TemplateSide::kFront);
  EXPECT_EQ(front.at(1, 0), 2);  // robot's left is the viewer's right; depth = x.
  const TemplateView back = ViewTemplate(t, TemplateSide::kBack);
  EXPECT_EQ(back.at(-2, 0), -3);  // mirrored: voxel 1 -> -2, x 2 -> depth -3.
  const TemplateView left = ViewTemplate(t, TemplateSide::kLeft);
  EXPECT_EQ(left.at(-3, 0), 1);
  const TemplateView top = ViewTemplate(t, TemplateSide::kTop);
  EXPECT_EQ(top.at(-2, 2), 0);
  EXPECT_EQ(front.at(0, 0), TemplateView::kEmpty);
}

TEST(TemplateShapeTest, ViewsMarkTheCellsWhoseNearestVoxelIsOnAFreeLimb) {
  // Two voxels one behind the other seen from the front, and a third beside them; the front one
  // (x = 2) and the one beside hold surface on a free limb, the back one (x = 0) does not.
  VoxelTemplate t;
  t.resolution_m = kRes;
  t.voxels = {Centre(0, 0, 1), Centre(2, 0, 1), Centre(0, 1, 3)};
  t.surface = {Centre(0, 0, 1), Centre(2, 0, 1), Centre(0, 1, 3)};
  t.free_limb = {0, 1, 1};
  const TemplateView front = ViewTemplate(t, TemplateSide::kFront);
  ASSERT_EQ(front.free_limb.size(), front.depth.size());
  auto limb = [](const TemplateView& v, int u, int row) {
    return v.free_limb[(row - v.v_min) * v.columns() + (u + v.half_width)];
  };
  EXPECT_EQ(front.at(0, 1), 2);
  EXPECT_EQ(limb(front, 0, 1), 1);  // the nearest voxel is the limb's.
  EXPECT_EQ(limb(front, 1, 3), 1);
  // From the back the nearest voxel of that column is the one off the limb.
  const TemplateView back = ViewTemplate(t, TemplateSide::kBack);
  EXPECT_EQ(back.at(-1, 1), -1);  // depth ~x: x 0 gives -1, nearer than x 2 (-3).
  EXPECT_EQ(limb(back, -1, 1), 0);
  // Without marks nothing is marked.
  t.free_limb.clear();
  const TemplateView plain = ViewTemplate(t, TemplateSide::kFront);
  EXPECT_EQ(limb(plain, 0, 1), 0);
}

TEST(TemplateShapeTest, SymmetricBlockHasNoAsymmetry) {
  const TemplateShape s = DescribeTemplate(Block());
  EXPECT_EQ(s.voxels, 6u * 8u * 10u);
  EXPECT_NEAR(s.height_m, 0.2, 1e-6);
  EXPECT_NEAR(s.width_x_m, 0.12, 1e-6);
  EXPECT_NEAR(s.width_y_m, 0.16, 1e-6);
  EXPECT_NEAR(s.min.x(), -0.06, 1e-6);
  EXPECT_DOUBLE_EQ(s.front_back_difference, 0.0);
  EXPECT_DOUBLE_EQ(s.left_right_difference, 0.0);
  EXPECT_DOUBLE_EQ(s.mirror_difference, 0.0);
}

TEST(TemplateShapeTest, BumpsShowInTheRightNumbers) {
  // A pack three voxels deep on the back (-x), centred: front and back differ (depths within
  // one voxel count as equal, so it must stand out more), the robot stays mirror symmetric.
  VoxelTemplate pack = Block();
  for (int z = 3; z < 7; ++z)
    for (int y = -2; y < 2; ++y)
      for (int x = -6; x < -3; ++x) pack.voxels.push_back(Centre(x, y, z));
  const TemplateShape p = DescribeTemplate(pack);
  EXPECT_GT(p.front_back_difference, 0.1);
  EXPECT_DOUBLE_EQ(p.mirror_difference, 0.0);
  // An arm raised on the left (+y) only: no longer mirror symmetric.
  VoxelTemplate arm = Block();
  for (int z = 10; z < 16; ++z) arm.voxels.push_back(Centre(0, 3, z));
  const TemplateShape a = DescribeTemplate(arm);
  EXPECT_GT(a.mirror_difference, 0.05);
  EXPECT_GT(a.front_back_difference, 0.05);  // seen from behind the arm is on the other side
  EXPECT_NEAR(a.height_m, 0.32, 1e-6);
}

}  // namespace
}  // namespace hpose
