#include "core/scoring/free_space.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "core/common/pose2d.h"

namespace hpose {
namespace {

// A sensor at `height` m looking along +x, pitched down by `pitch` rad, yawed by `yaw`: the
// sensor frame (x right, y down, z forward) from the ground frame (x forward, z up).
Eigen::Isometry3d SensorFromGround(double height, double pitch, double yaw) {
  Eigen::Matrix3d ground_from_level;
  // Columns: the sensor's x (right), y (down), z (forward) axes in the ground frame.
  ground_from_level << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  const Eigen::Matrix3d ground_from_sensor =
      Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * ground_from_level *
      Eigen::AngleAxisd(-pitch, Eigen::Vector3d::UnitX()).toRotationMatrix();
  Eigen::Isometry3d g = Eigen::Isometry3d::Identity();
  g.linear() = ground_from_sensor;
  g.translation() = Eigen::Vector3d(0.0, 0.0, height);
  return g.inverse();
}

// What a sensor sees of a floor plus a few boxes, as a cloud in the sensor frame.
PointCloud SceneCloud(const Eigen::Isometry3d& sensor_from_ground, std::mt19937* rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::Isometry3d ground_from_sensor = sensor_from_ground.inverse();
  const Eigen::Vector3d origin = ground_from_sensor.translation();
  // Boxes: centre (x, y), half sizes, height.
  struct Box {
    double x, y, hx, hy, h;
  };
  std::vector<Box> boxes;
  for (int i = 0; i < 4; ++i) {
    boxes.push_back({2.0 + 1.5 * u(*rng), 0.8 * u(*rng), 0.1 + 0.1 * std::abs(u(*rng)),
                     0.1 + 0.1 * std::abs(u(*rng)), 0.3 + 0.4 * std::abs(u(*rng))});
  }
  PointCloud cloud;
  for (int v = 0; v < 120; ++v) {
    for (int c = 0; c < 160; ++c) {
      const Eigen::Vector3d dir_s((c - 80) / 140.0, (v - 60) / 140.0, 1.0);
      const Eigen::Vector3d dir = ground_from_sensor.linear() * dir_s;
      double best = 1e9;
      if (dir.z() < -1e-6) best = -origin.z() / dir.z();
      for (const Box& b : boxes) {  // slab test.
        double t0 = 0.0, t1 = 1e9;
        const double lo[3] = {b.x - b.hx, b.y - b.hy, 0.0};
        const double hi[3] = {b.x + b.hx, b.y + b.hy, b.h};
        bool hit = true;
        for (int k = 0; k < 3 && hit; ++k) {
          if (std::abs(dir[k]) < 1e-12) {
            hit = origin[k] >= lo[k] && origin[k] <= hi[k];
            continue;
          }
          double a = (lo[k] - origin[k]) / dir[k], e = (hi[k] - origin[k]) / dir[k];
          if (a > e) std::swap(a, e);
          t0 = std::max(t0, a);
          t1 = std::min(t1, e);
          hit = t0 <= t1;
        }
        if (hit) best = std::min(best, t0);
      }
      if (best > 8.0 / dir_s.norm() || (v + c) % 37 == 0) {
        cloud.points.emplace_back(NAN, NAN, NAN);  // no return.
        continue;
      }
      cloud.points.push_back((dir_s * best).cast<float>());
    }
  }
  return cloud;
}

TEST(FreeSpaceTest, ColumnFormEqualsTheReferenceCellForCell) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int total_free = 0;
  for (int trial = 0; trial < 12; ++trial) {
    const double height = 0.3 + 1.7 * u(rng), pitch = DegToRad(40.0 * u(rng));
    const double yaw = DegToRad(-20.0 + 40.0 * u(rng));
    const Eigen::Isometry3d sensor_from_ground = SensorFromGround(height, pitch, yaw);
    const PointCloud cloud = SceneCloud(sensor_from_ground, &rng);
    const RangeImage range = RangeImage::FromCloud(cloud, 100.0);
    const double res = 0.016;
    const Eigen::Vector3i lo(static_cast<int>(0.5 / res), static_cast<int>(-1.2 / res), 0);
    const Eigen::Vector3i hi(static_cast<int>(4.0 / res), static_cast<int>(1.2 / res), 45);
    FreeSpaceOptions options;
    options.margin_m = 0.01 + 0.03 * u(rng);
    const ClusterVoxels fast = FreeSpaceCells(range, sensor_from_ground, lo, hi, res, options);
    const ClusterVoxels ref =
        FreeSpaceCellsReference(range, sensor_from_ground, lo, hi, res, options);
    ASSERT_EQ(fast.cells.size(), ref.cells.size()) << "trial " << trial;
    for (size_t i = 0; i < ref.cells.size(); ++i) {
      ASSERT_EQ(fast.cells[i], ref.cells[i]) << "trial " << trial << " cell " << i;
    }
    // The four-lane form (what CPUs without AVX-512 run; FreeSpaceCells is the eight-lane one
    // where the CPU has it) over the same box.
    FreeSpaceRegion box;
    box.core_lo = lo.head<2>();
    box.core_hi = hi.head<2>();
    box.z_lo = lo.z();
    box.grow.assign(hi.z() - lo.z() + 1, 0);
    ASSERT_EQ(FreeSpaceCellsFourLanes(range, sensor_from_ground, box, res, options).cells,
              ref.cells)
        << "trial " << trial;
    // And the eight-lane AVX2 form (what CPUs with AVX2 but no AVX-512 run).
    if (FreeSpaceAvx2Available()) {
      ASSERT_EQ(FreeSpaceCellsAvx2(range, sensor_from_ground, box, res, options).cells, ref.cells)
          << "trial " << trial;
    }
    total_free += static_cast<int>(ref.cells.size());
  }
  EXPECT_GT(total_free, 10000);  // the scenes leave plenty of free space to compare.
}

// A region grown differently per layer (some layers not at all, some left out) holds the
// reference's cells of that region, which are the box's cells within it.
TEST(FreeSpaceTest, RegionGrownPerLayerEqualsTheReferenceAndTheBoxWithinIt) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::uniform_int_distribution<int> g(-1, 20);
  int total_free = 0, left_out = 0;
  for (int trial = 0; trial < 8; ++trial) {
    const double height = 0.3 + 1.2 * u(rng), pitch = DegToRad(30.0 * u(rng));
    const Eigen::Isometry3d sensor_from_ground = SensorFromGround(height, pitch, 0.0);
    const PointCloud cloud = SceneCloud(sensor_from_ground, &rng);
    const RangeImage range = RangeImage::FromCloud(cloud, 100.0);
    const double res = 0.016;
    FreeSpaceRegion region;
    region.core_lo = Eigen::Vector2i(static_cast<int>(1.0 / res), static_cast<int>(-0.3 / res));
    region.core_hi = region.core_lo + Eigen::Vector2i(8 + trial, 12);
    region.z_lo = trial % 3;
    for (int z = 0; z < 41 + trial; ++z) region.grow.push_back(z == 5 ? -1 : g(rng));
    const ClusterVoxels fast = FreeSpaceCells(range, sensor_from_ground, region, res);
    const ClusterVoxels ref = FreeSpaceCellsReference(range, sensor_from_ground, region, res);
    ASSERT_EQ(fast.cells, ref.cells) << "trial " << trial;
    ASSERT_EQ(FreeSpaceCellsFourLanes(range, sensor_from_ground, region, res).cells, ref.cells)
        << "trial " << trial;
    if (FreeSpaceAvx2Available()) {
      ASSERT_EQ(FreeSpaceCellsAvx2(range, sensor_from_ground, region, res).cells, ref.cells)
          << "trial " << trial;
    }
    // The box around the largest growth, filtered to the region.
    const int most = *std::max_element(region.grow.begin(), region.grow.end());
    const Eigen::Vector3i lo(region.core_lo.x() - most, region.core_lo.y() - most, region.z_lo);
    const Eigen::Vector3i hi(region.core_hi.x() + most, region.core_hi.y() + most,
                             region.z_lo + static_cast<int>(region.grow.size()) - 1);
    std::vector<Eigen::Vector3i> within;
    for (const Eigen::Vector3i& c : FreeSpaceCells(range, sensor_from_ground, lo, hi, res).cells) {
      const int out = std::max({0, region.core_lo.x() - c.x(), c.x() - region.core_hi.x(),
                                region.core_lo.y() - c.y(), c.y() - region.core_hi.y()});
      if (region.grow[c.z() - region.z_lo] >= out) {
        within.push_back(c);
      } else {
        ++left_out;
      }
    }
    ASSERT_EQ(fast.cells, within) << "trial " << trial;
    total_free += static_cast<int>(fast.cells.size());
  }
  EXPECT_GT(total_free, 5000);
  EXPECT_GT(left_out, 5000);
}

TEST(FreeSpaceTest, RegionAroundAClusterIsItsColumnsBoxGrownFromTheFloor) {
  ClusterVoxels voxels;
  voxels.resolution_m = 0.016;
  voxels.cells = {{3, -2, 5}, {7, 4, 0}, {-1, 1, 9}, {5, 0, 2}};
  const FreeSpaceRegion region = FreeSpaceRegionAround(voxels, {4, 4, 3, -1});
  EXPECT_EQ(region.core_lo, Eigen::Vector2i(-1, -2));
  EXPECT_EQ(region.core_hi, Eigen::Vector2i(7, 4));
  EXPECT_EQ(region.z_lo, 0);
  EXPECT_EQ(region.grow, (std::vector<int>{4, 4, 3, -1}));
}

TEST(FreeSpaceTest, CellsBeforeASurfaceAreFreeAndBehindItAreNot) {
  // A wall across the view 3 m ahead of a level sensor 1 m up.
  const Eigen::Isometry3d sensor_from_ground = SensorFromGround(1.0, 0.0, 0.0);
  PointCloud cloud;
  for (int v = -60; v <= 60; ++v) {
    for (int c = -80; c <= 80; ++c) {
      cloud.points.emplace_back(c / 100.0f * 3.0f, v / 100.0f * 3.0f, 3.0f);
    }
  }
  const RangeImage range = RangeImage::FromCloud(cloud, 100.0);
  const double res = 0.016;
  const Eigen::Vector3i lo(static_cast<int>(1.0 / res), -3, 60);
  const Eigen::Vector3i hi(static_cast<int>(4.0 / res), 3, 64);
  const ClusterVoxels free = FreeSpaceCells(range, sensor_from_ground, lo, hi, res);
  ASSERT_FALSE(free.cells.empty());
  int near = 0;
  for (const Eigen::Vector3i& c : free.cells) {
    const double x = (c.x() + 0.5) * res;
    // Free only clearly before the wall (its noise and the margin), never at or behind it.
    EXPECT_LT(x, 3.0 - 0.024) << c.transpose();
    near += x < 2.8 ? 1 : 0;
  }
  // Every cell up to 2.8 m along the seven columns and five heights is free.
  EXPECT_EQ(near, 7 * 5 * (static_cast<int>(2.8 / res - 0.5) - lo.x() + 1));
}

}  // namespace
}  // namespace hpose
