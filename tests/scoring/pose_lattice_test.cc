#include "core/scoring/pose_lattice.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace hpose {
namespace {

TEST(FloorDivTest, MatchesMathematicalFloor) {
  for (int a = -40; a <= 40; ++a) {
    for (int b : {1, 2, 3, 4, 7, 8}) {
      EXPECT_EQ(FloorDiv(a, b), static_cast<int>(std::floor(static_cast<double>(a) / b)))
          << a << "/" << b;
    }
  }
}

TEST(PoseLatticeTest, PoseConversionsRoundTrip) {
  const PoseLattice lattice;
  EXPECT_DOUBLE_EQ(lattice.step_m(), 0.004);
  const LatticePose p{-25, 250, 270};
  const Pose2D pose = ToPose(lattice, p);
  EXPECT_NEAR(pose.x, -0.1, 1e-12);
  EXPECT_NEAR(pose.y, 1.0, 1e-12);
  EXPECT_NEAR(pose.theta, -kPi / 2, 1e-12);
  EXPECT_EQ(NearestLatticePose(lattice, pose), p);
  EXPECT_EQ(WrapAngleIndex(lattice, -1), 359);
  EXPECT_EQ(WrapAngleIndex(lattice, 720), 0);
  EXPECT_NEAR(ToPose(lattice, {0, 0, 180}).theta, kPi, 1e-12);
}

TEST(PoseLatticeTest, ValidateNamesTheBadField) {
  PoseLattice l;
  l.subdivisions = 0;
  ASSERT_FALSE(l.Validate().ok());
  EXPECT_NE(l.Validate().error().message.find("subdivisions"), std::string::npos);
  l = PoseLattice();
  l.resolution_m = -1;
  EXPECT_FALSE(l.Validate().ok());
}

// The placed cell equals floor((R p + t) / resolution) computed directly, except where R p + t
// lies within rounding distance of a cell boundary (the quantisation of R p decides there).
TEST(PoseLatticeTest, PlacedCellIsTheCellOfTheTransformedPoint) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-0.3f, 0.3f), h(0.0f, 0.6f);
  for (int subdivisions : {1, 2, 4, 8}) {
    PoseLattice lattice;
    lattice.subdivisions = subdivisions;
    VoxelTemplate tpl;
    tpl.name = "t";
    for (int i = 0; i < 300; ++i) tpl.voxels.emplace_back(u(rng), u(rng), h(rng));
    int checked = 0;
    for (int itheta : {0, 1, 45, 90, 133, 180, 359}) {
      const RotatedTemplate r = RotateTemplate(tpl, lattice, itheta);
      const double th = itheta * lattice.angle_step_rad();
      for (int ix : {-300, -17, 0, 5, 251}) {
        for (int iy : {-99, 0, 3, 400}) {
          for (size_t k = 0; k < tpl.voxels.size(); ++k) {
            const Eigen::Vector3f& p = tpl.voxels[k];
            const double x = std::cos(th) * p.x() - std::sin(th) * p.y() + ix * lattice.step_m();
            const double y = std::sin(th) * p.x() + std::cos(th) * p.y() + iy * lattice.step_m();
            const double fx = x / lattice.resolution_m, fy = y / lattice.resolution_m;
            if (std::abs(fx - std::round(fx)) < 1e-6 || std::abs(fy - std::round(fy)) < 1e-6) {
              continue;
            }
            const Eigen::Vector3i c = PlacedCell(r.sub_cells[k], ix, iy, subdivisions);
            ASSERT_EQ(c.x(), static_cast<int>(std::floor(fx)));
            ASSERT_EQ(c.y(), static_cast<int>(std::floor(fy)));
            ASSERT_EQ(c.z(), static_cast<int>(std::floor(p.z() / lattice.resolution_m)));
            ++checked;
          }
        }
      }
    }
    EXPECT_GT(checked, 30000);
  }
}

TEST(TemplateRotationsTest, PrecomputesEveryAngle) {
  VoxelTemplate tpl;
  tpl.name = "t";
  tpl.voxels = {{0.1f, 0.0f, 0.2f}, {0.0f, 0.05f, 0.3f}};
  const PoseLattice lattice;
  const TemplateRotations rot(tpl, lattice);
  EXPECT_EQ(rot.Get(90).itheta, 90);
  // 90 degrees turns +x into +y: q = floor(0.1 * 4 / 0.016) = 25 on the y axis.
  EXPECT_EQ(rot.Get(90).sub_cells[0].y(), 25);
  EXPECT_EQ(rot.Get(0).sub_cells[0].x(), 25);
}

// TemplateRotations computes per column of the template (points of equal x, y) what
// RotatePoints computes per point: the same rotated template at every angle.
TEST(TemplateRotationsTest, EqualsRotatingEveryPoint) {
  VoxelTemplate tpl;
  tpl.name = "t";
  tpl.resolution_m = 0.016;
  for (int i = 0; i < 40; ++i) {
    const float x = 0.013f * static_cast<float>(i % 7) - 0.04f;
    const float y = 0.017f * static_cast<float>(i % 5) - 0.03f;
    tpl.voxels.emplace_back(x, y, 0.016f * static_cast<float>(i % 11));
    tpl.voxels.emplace_back(x, y, 0.016f * static_cast<float>(i % 11) + 0.5f);
  }
  const PoseLattice lattice;
  const TemplateRotations rot(tpl, lattice);
  const std::vector<Eigen::Vector3f> points = tpl.VoxelSurfaceCentroids();
  for (int t = 0; t < lattice.angle_steps; t += 7) {
    const RotatedTemplate a = RotatePoints(points, lattice, t);
    const RotatedTemplate& b = rot.Get(t);
    EXPECT_EQ(a.itheta, b.itheta);
    EXPECT_EQ(a.sub_cells, b.sub_cells) << t;
    EXPECT_EQ(a.column_q, b.column_q) << t;
    EXPECT_EQ(a.column_masks, b.column_masks) << t;
    EXPECT_EQ(a.q_min, b.q_min) << t;
    EXPECT_EQ(a.q_max, b.q_max) << t;
    EXPECT_EQ(a.z_base, b.z_base) << t;
    EXPECT_EQ(a.z_words, b.z_words) << t;
  }
}

}  // namespace
}  // namespace hpose
