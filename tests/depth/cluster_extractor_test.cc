#include "core/depth/cluster_extractor.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "tests/depth/synthetic_scene.h"

namespace hpose {
namespace {

using testing_scene::Box;
using testing_scene::Cylinder;
using testing_scene::GroundFromSensor;
using testing_scene::Render;
using testing_scene::RenderOptions;
using testing_scene::Scene;

constexpr double kDeg = M_PI / 180.0;

// Dense samples of the surface of an axis-aligned box (ground frame), one layer per face, about
// 5 mm apart (integer steps, so opposite faces get the same number of samples).
void AddBoxSurface(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi,
                   std::vector<Eigen::Vector3f>* out) {
  int n[3];
  for (int a = 0; a < 3; ++a)
    n[a] = std::max(1, static_cast<int>(std::lround((hi[a] - lo[a]) / 0.005f)));
  for (int i = 0; i <= n[0]; ++i) {
    for (int j = 0; j <= n[1]; ++j) {
      for (int k = 0; k <= n[2]; ++k) {
        const bool on_face = i == 0 || i == n[0] || j == 0 || j == n[1] || k == 0 || k == n[2];
        if (!on_face) continue;
        out->emplace_back(lo.x() + (hi.x() - lo.x()) * i / n[0],
                          lo.y() + (hi.y() - lo.y()) * j / n[1],
                          lo.z() + (hi.z() - lo.z()) * k / n[2]);
      }
    }
  }
}

// A ground-frame point set moved into the sensor frame of `floor`.
PointCloud ToSensor(const std::vector<Eigen::Vector3f>& ground, const FloorEstimate& floor) {
  const Eigen::Isometry3f sensor_from_ground = floor.ground_from_sensor.inverse().cast<float>();
  PointCloud cloud;
  for (const Eigen::Vector3f& g : ground) cloud.points.push_back(sensor_from_ground * g);
  return cloud;
}

Eigen::Vector3f MeanAbove(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& lo,
                          const Eigen::Vector3f& hi, float min_z) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int n = 0;
  for (const Eigen::Vector3f& p : points) {
    if ((p.array() >= lo.array() - 1e-4f).all() && (p.array() <= hi.array() + 1e-4f).all() &&
        p.z() >= min_z) {
      sum += p.cast<double>();
      ++n;
    }
  }
  return (sum / n).cast<float>();
}

class ClusterExtractorMountTest : public ::testing::TestWithParam<std::tuple<double, double>> {};

TEST_P(ClusterExtractorMountTest, SeparatesBoxesAndReportsTheirCentroids) {
  const auto [height, pitch_deg] = GetParam();
  const FloorEstimate floor = FloorEstimate::FromHeightPitchRoll(height, pitch_deg * kDeg, 0.0);
  std::vector<Eigen::Vector3f> ground;
  // Floor patch (must disappear), three boxes 0.3-0.6 m apart, flat debris (too low).
  for (float x = 0.5f; x < 3.5f; x += 0.01f) {
    for (float y = -1.5f; y < 1.5f; y += 0.01f) ground.emplace_back(x, y, 0.0f);
  }
  const Eigen::Vector3f lo[3] = {{1.0f, -0.2f, 0.0f}, {1.8f, 0.5f, 0.0f}, {2.4f, -0.9f, 0.0f}};
  const Eigen::Vector3f hi[3] = {{1.3f, 0.1f, 0.58f}, {2.0f, 0.8f, 0.3f}, {2.6f, -0.7f, 1.2f}};
  for (int b = 0; b < 3; ++b) AddBoxSurface(lo[b], hi[b], &ground);
  AddBoxSurface({1.0f, 0.8f, 0.0f}, {1.3f, 1.1f, 0.05f}, &ground);  // 5 cm tall: debris.

  const PointCloud cloud = ToSensor(ground, floor);
  const ClusterOptions options;
  const Result<std::vector<Cluster>> clusters = ExtractClusters(cloud, floor, options);
  ASSERT_TRUE(clusters.ok()) << clusters.error().ToString();
  ASSERT_EQ(clusters->size(), 3u);
  for (size_t i = 1; i < clusters->size(); ++i) {
    EXPECT_GE((*clusters)[i - 1].points.size(), (*clusters)[i].points.size());
  }
  for (int b = 0; b < 3; ++b) {
    const Eigen::Vector3f box_centre = 0.5f * (lo[b] + hi[b]);
    const auto match = std::find_if(clusters->begin(), clusters->end(), [&](const Cluster& c) {
      return (c.centroid.head<2>() - box_centre.head<2>()).norm() < 0.1f;
    });
    ASSERT_NE(match, clusters->end()) << "box " << b;
    const Eigen::Vector3f expected =
        MeanAbove(ground, lo[b], hi[b], static_cast<float>(options.min_height_above_floor_m));
    EXPECT_LT((match->centroid - expected).norm(), 0.02f) << "box " << b;
    EXPECT_NEAR(match->height(), hi[b].z(), 0.01);
    EXPECT_NEAR(match->min.x(), lo[b].x(), 0.01);
    EXPECT_NEAR(match->max.y(), hi[b].y(), 0.01);
    EXPECT_GE(match->min.z(), options.min_height_above_floor_m - 1e-3);
    for (const Eigen::Vector3f& p : match->points) {
      ASSERT_TRUE((p.array() >= lo[b].array() - 0.01f).all() &&
                  (p.array() <= hi[b].array() + 0.01f).all());
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Mounts, ClusterExtractorMountTest,
                         ::testing::Values(std::make_tuple(0.34, 0.0), std::make_tuple(1.0, 30.0),
                                           std::make_tuple(2.5, 60.0)));

TEST(ClusterExtractorTest, ObjectsCloserThanTheToleranceMerge) {
  const FloorEstimate floor = FloorEstimate::FromHeightPitchRoll(1.0, 20 * kDeg, 0.0);
  std::vector<Eigen::Vector3f> ground;
  AddBoxSurface({1.5f, 0.0f, 0.0f}, {1.8f, 0.3f, 0.5f}, &ground);
  AddBoxSurface({1.5f, 0.32f, 0.0f}, {1.8f, 0.6f, 0.5f}, &ground);  // 2 cm gap < 4 cm.
  AddBoxSurface({1.5f, 0.7f, 0.0f}, {1.8f, 1.0f, 0.5f}, &ground);   // 10 cm gap.
  const Result<std::vector<Cluster>> clusters =
      ExtractClusters(ToSensor(ground, floor), floor, ClusterOptions{});
  ASSERT_TRUE(clusters.ok());
  ASSERT_EQ(clusters->size(), 2u);
  EXPECT_NEAR((*clusters)[0].max.y() - (*clusters)[0].min.y(), 0.6, 0.01);
  EXPECT_NEAR((*clusters)[1].centroid.y(), 0.85, 0.02);
}

TEST(ClusterExtractorTest, FiltersByHeightFootprintAndSize) {
  const FloorEstimate floor = FloorEstimate::FromHeightPitchRoll(1.0, 20 * kDeg, 0.0);
  std::vector<Eigen::Vector3f> ground;
  AddBoxSurface({1.5f, -1.0f, 0.0f}, {1.7f, 1.0f, 0.4f}, &ground);      // 2 m wide: too wide.
  AddBoxSurface({2.5f, 0.0f, 0.0f}, {2.516f, 0.016f, 0.12f}, &ground);  // post: few points.
  AddBoxSurface({3.0f, 0.0f, 0.0f}, {3.3f, 0.3f, 0.6f}, &ground);       // kept.
  const PointCloud cloud = ToSensor(ground, floor);
  Result<std::vector<Cluster>> clusters = ExtractClusters(cloud, floor, ClusterOptions{});
  ASSERT_TRUE(clusters.ok());
  ASSERT_EQ(clusters->size(), 1u);
  EXPECT_NEAR((*clusters)[0].centroid.x(), 3.15, 0.03);

  ClusterOptions loose;
  loose.max_footprint_m = 2.5;
  loose.min_points = 10;
  clusters = ExtractClusters(cloud, floor, loose);
  ASSERT_TRUE(clusters.ok());
  EXPECT_EQ(clusters->size(), 3u);

  ClusterOptions short_only;
  short_only.max_height_m = 0.5;
  short_only.max_footprint_m = 2.5;
  clusters = ExtractClusters(cloud, floor, short_only);
  ASSERT_TRUE(clusters.ok());
  ASSERT_EQ(clusters->size(), 1u);
  EXPECT_NEAR((*clusters)[0].height(), 0.4, 0.01);
}

TEST(ClusterExtractorTest, SplitsTwoTouchingPeopleButNotAnArm) {
  const FloorEstimate floor = FloorEstimate::FromHeightPitchRoll(1.2, 10 * kDeg, 0.0);
  std::vector<Eigen::Vector3f> ground;
  // Two 1.7 m "people" whose shoulders touch (boxes overlapping by 1 cm).
  AddBoxSurface({2.0f, -0.4f, 0.0f}, {2.25f, 0.01f, 1.45f}, &ground);
  AddBoxSurface({2.0f, -0.25f, 1.45f}, {2.2f, -0.1f, 1.7f}, &ground);  // head.
  AddBoxSurface({2.0f, 0.0f, 0.0f}, {2.25f, 0.4f, 1.45f}, &ground);
  AddBoxSurface({2.0f, 0.12f, 1.45f}, {2.2f, 0.27f, 1.68f}, &ground);
  // A small robot with a raised arm next to its head (the arm is the highest point).
  AddBoxSurface({1.0f, -1.2f, 0.0f}, {1.12f, -1.0f, 0.5f}, &ground);
  AddBoxSurface({1.02f, -1.14f, 0.5f}, {1.1f, -1.06f, 0.58f}, &ground);
  AddBoxSurface({1.03f, -0.98f, 0.3f}, {1.07f, -0.94f, 0.75f}, &ground);
  ClusterOptions split;  // the split is off by default; this tests it when asked for.
  split.split_min_top_separation_m = 0.2;
  const Result<std::vector<Cluster>> clusters =
      ExtractClusters(ToSensor(ground, floor), floor, split);
  ASSERT_TRUE(clusters.ok());
  ASSERT_EQ(clusters->size(), 3u);
  int people = 0;
  for (const Cluster& c : *clusters) {
    if (c.height() > 1.5f) {
      ++people;
      EXPECT_NEAR(std::abs(c.centroid.y()), 0.2, 0.08);  // split at the bisector of the tops.
    } else {
      EXPECT_NEAR(c.height(), 0.75, 0.01);  // the robot kept its arm.
    }
  }
  EXPECT_EQ(people, 2);
  ClusterOptions no_split;
  no_split.split_min_top_separation_m = 0.0;
  const Result<std::vector<Cluster>> merged =
      ExtractClusters(ToSensor(ground, floor), floor, no_split);
  ASSERT_TRUE(merged.ok());
  EXPECT_EQ(merged->size(), 2u);
}

TEST(ClusterExtractorTest, DropsVeilPointsBetweenAPersonAndAWallBehind) {
  // Render an organised view, then add mixed pixels interpolated across the depth jump at the
  // person's silhouette, as a structured-light sensor does.
  const Eigen::Isometry3d pose = GroundFromSensor(1.0, 0.0, 0.0);
  Scene scene;
  scene.cylinders.push_back(Cylinder{2.0, 0.0, 0.2, 1.7});
  scene.boxes.push_back(Box{{2.3, -0.7, 0.0}, {2.4, 0.7, 1.2}});  // a low wall behind.
  RenderOptions render;
  render.organised = true;
  const Intrinsics k = Intrinsics::KinectV1(320, 240);
  PointCloud cloud = Render(scene, pose, k, render);
  // Replace the pixels around every horizontal depth jump by a ramp interpolated between the
  // two sides, as a structured-light sensor's mixed pixels do.
  constexpr int kHalf = 6;
  for (int v = 0; v < k.height; ++v) {
    Eigen::Vector3f* row = cloud.points.data() + static_cast<size_t>(v) * k.width;
    std::vector<int> jumps;
    for (int u = kHalf; u + kHalf + 1 < k.width; ++u) {
      if (row[u].allFinite() && row[u + 1].allFinite() &&
          std::abs(row[u].z() - row[u + 1].z()) > 0.1f) {
        jumps.push_back(u);
      }
    }
    for (const int u : jumps) {
      const float z0 = row[u - kHalf].z();
      const float z1 = row[u + kHalf + 1].z();
      for (int i = -kHalf + 1; i <= kHalf; ++i) {
        Eigen::Vector3f& p = row[u + i];
        if (!p.allFinite()) continue;
        const float t = static_cast<float>(i + kHalf) / (2 * kHalf + 1);
        p *= ((1 - t) * z0 + t * z1) / p.z();
      }
    }
  }
  const FloorEstimate floor = FloorEstimate::FromHeightPitchRoll(1.0, 0.0, 0.0);
  ClusterOptions options;
  options.min_points = 50;
  options.split_min_top_separation_m = 0.0;  // isolate the veil filter.
  // The person's cluster is the tallest; with the filter it is the person alone.
  auto tallest = [](const std::vector<Cluster>& clusters) {
    return *std::max_element(
        clusters.begin(), clusters.end(),
        [](const Cluster& a, const Cluster& b) { return a.height() < b.height(); });
  };
  Result<std::vector<Cluster>> clusters = ExtractClusters(cloud, floor, options);
  ASSERT_TRUE(clusters.ok());
  ASSERT_GE(clusters->size(), 2u);  // the person and the wall (maybe cut in two by it).
  Cluster person = tallest(*clusters);
  EXPECT_NEAR(person.height(), 1.7, 0.02);
  EXPECT_LT(person.max.y() - person.min.y(), 0.45);
  EXPECT_LT(person.max.x(), 2.25f);  // nothing of the wall.
  options.veil_max_angle_rad = 0.0;
  options.max_footprint_m = 5.0;  // keep the glued cluster visible.
  clusters = ExtractClusters(cloud, floor, options);
  ASSERT_TRUE(clusters.ok());
  ASSERT_FALSE(clusters->empty());
  person = tallest(*clusters);
  EXPECT_GT(person.max.y() - person.min.y(), 1.0)
      << "without the veil filter the mixed pixels glue the wall to the person";
}

TEST(ClusterExtractorTest, DropsClustersCutByTheRangeLimit) {
  const FloorEstimate floor = FloorEstimate::FromHeightPitchRoll(1.0, 10 * kDeg, 0.0);
  std::vector<Eigen::Vector3f> ground;
  AddBoxSurface({4.8f, -0.3f, 0.0f}, {5.4f, 0.3f, 1.0f}, &ground);  // crosses 5 m.
  AddBoxSurface({3.0f, -0.3f, 0.0f}, {3.3f, 0.0f, 1.0f}, &ground);
  const Result<std::vector<Cluster>> clusters =
      ExtractClusters(ToSensor(ground, floor), floor, ClusterOptions{});
  ASSERT_TRUE(clusters.ok());
  ASSERT_EQ(clusters->size(), 1u);
  EXPECT_LT((*clusters)[0].max.x(), 3.4f);
}

TEST(ClusterExtractorTest, EmptyAndFloorOnlyCloudsGiveNoClusters) {
  const FloorEstimate floor = FloorEstimate::FromHeightPitchRoll(1.0, 30 * kDeg, 0.0);
  Result<std::vector<Cluster>> clusters = ExtractClusters(PointCloud{}, floor);
  ASSERT_TRUE(clusters.ok());
  EXPECT_TRUE(clusters->empty());
  const PointCloud floor_only =
      Render(Scene{}, GroundFromSensor(1.0, 30 * kDeg, 0.0), Intrinsics::KinectV1(160, 120));
  clusters = ExtractClusters(floor_only, floor);
  ASSERT_TRUE(clusters.ok());
  EXPECT_TRUE(clusters->empty());
  PointCloud nans;
  nans.points.assign(10, Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN()));
  clusters = ExtractClusters(nans, floor);
  ASSERT_TRUE(clusters.ok());
  EXPECT_TRUE(clusters->empty());
}

// A box the size of a small humanoid under a sensor near the ceiling looking steeply down: the
// floor 3 m away is noisy in height (Kinect v1's axial noise with its disparity steps, about
// 1.7e-3 z^2), and its speckle above 4 cm is counted as floor too while within four standard
// deviations of the noise's vertical part (SteepViewTest has what it does to a whole frame).
TEST(ClusterExtractorTest, ANoisyFloorSeenFromAboveStaysFloor) {
  const double height = 2.95, pitch = 80 * kDeg;
  Scene scene;
  scene.boxes.push_back(Box{{0.35, -0.15, 0.0}, {0.55, 0.15, 0.58}});
  RenderOptions render;
  render.organised = true;
  const Intrinsics kinect = Intrinsics::KinectV1(640, 480);
  PointCloud cloud = Render(scene, GroundFromSensor(height, pitch, 0.0), kinect, render);
  // The noise alike over 6 x 6 pixels, as window-matched disparities are (independent pixels
  // would stand out of their neighbours, and the veil filter would drop them).
  std::mt19937 rng(7);
  std::normal_distribution<float> unit(0.0f, 1.0f);
  constexpr int kBlock = 6;
  for (int bv = 0; bv < kinect.height; bv += kBlock) {
    for (int bu = 0; bu < kinect.width; bu += kBlock) {
      const float n = unit(rng);
      for (int v = bv; v < bv + kBlock; ++v) {
        for (int u = bu; u < bu + kBlock; ++u) {
          Eigen::Vector3f& p = cloud.points[static_cast<size_t>(v) * kinect.width + u];
          p *= 1.0f + 1.7e-3f * p.z() * n;  // sigma_z = 1.7e-3 z^2 along the ray.
        }
      }
    }
  }
  const FloorEstimate floor = FloorEstimate::FromHeightPitchRoll(height, pitch, 0.0);
  ClusterOptions options;
  options.min_points = 1;  // keep the speckle's clusters to count them.
  options.min_height_m = 0.0;
  Result<std::vector<Cluster>> clusters = ExtractClusters(cloud, floor, options);
  ASSERT_TRUE(clusters.ok());
  // The box's top (its sides are seen too obliquely to keep), and at most a couple of the
  // speckle's few points beyond 4 standard deviations.
  ASSERT_GE(clusters->size(), 1u);
  EXPECT_LE(clusters->size(), 3u) << "the floor's speckle left clusters of its own";
  const Cluster& box = (*clusters)[0];
  for (size_t c = 1; c < clusters->size(); ++c) EXPECT_LT((*clusters)[c].points.size(), 20u);
  EXPECT_NEAR(box.centroid.x(), 0.45, 0.03);
  EXPECT_NEAR(box.max.z(), 0.58, 0.03);
  EXPECT_GT(box.points.size(), 500u);
  EXPECT_LT(box.max.x() - box.min.x(), 0.25);
  EXPECT_LT(box.max.y() - box.min.y(), 0.35);
  // No point of it lies within the noise's reach: 4 x 1.65e-3 x depth x sensor height.
  const Eigen::Isometry3f sensor_from_ground = floor.ground_from_sensor.inverse().cast<float>();
  for (const Eigen::Vector3f& g : box.points) {
    const float depth = (sensor_from_ground * g).z();
    ASSERT_GE(g.z(), 4 * 1.65e-3f * depth * static_cast<float>(height) - 1e-5f);
  }

  options.floor_noise_sigmas = 0.0;
  clusters = ExtractClusters(cloud, floor, options);
  ASSERT_TRUE(clusters.ok());
  EXPECT_GT(clusters->size(), 30u) << "without the noise's reach the speckle stands on the floor";

  // A sensor 1 m high or lower never reaches 4 cm this way: the same clusters either way.
  const FloorEstimate low = FloorEstimate::FromHeightPitchRoll(0.9, 20 * kDeg, 0.0);
  scene.boxes[0] = Box{{2.0, -0.15, 0.0}, {2.2, 0.15, 0.58}};
  scene.boxes.push_back(Box{{3.9, 0.5, 0.0}, {4.2, 0.8, 0.3}});
  render.noise_sigma_k = 1.7e-3;
  const PointCloud far = Render(scene, GroundFromSensor(0.9, 20 * kDeg, 0.0), kinect, render);
  const Result<std::vector<Cluster>> with = ExtractClusters(far, low, ClusterOptions{});
  options.min_points = ClusterOptions{}.min_points;
  options.min_height_m = ClusterOptions{}.min_height_m;
  const Result<std::vector<Cluster>> without = ExtractClusters(far, low, options);
  ASSERT_TRUE(with.ok() && without.ok());
  ASSERT_EQ(with->size(), 2u);
  ASSERT_EQ(with->size(), without->size());
  for (size_t c = 0; c < with->size(); ++c) {
    EXPECT_EQ((*with)[c].points, (*without)[c].points) << "cluster " << c;
  }
}

TEST(ClusterExtractorTest, RejectsInvalidOptions) {
  const FloorEstimate floor = FloorEstimate::FromHeightPitchRoll(1.0, 30 * kDeg, 0.0);
  const char* fields[] = {"tolerance_m",       "min_points",         "max_height_above_floor_m",
                          "downsample_leaf_m", "floor_noise_sigmas", "floor_noise_sigmas"};
  ClusterOptions bad[6];
  bad[0].tolerance_m = 0.0;
  bad[1].min_points = 0;
  bad[2].max_height_above_floor_m = bad[2].min_height_above_floor_m;
  bad[3].downsample_leaf_m = -0.01;
  bad[4].floor_noise_sigmas = -1.0;
  bad[5].floor_noise_sigmas = std::numeric_limits<double>::quiet_NaN();
  for (int i = 0; i < 6; ++i) {
    const Result<std::vector<Cluster>> clusters = ExtractClusters(PointCloud{}, floor, bad[i]);
    ASSERT_FALSE(clusters.ok()) << fields[i];
    EXPECT_EQ(clusters.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(clusters.error().message.find(fields[i]), std::string::npos)
        << clusters.error().message;
  }
}

}  // namespace
}  // namespace hpose
