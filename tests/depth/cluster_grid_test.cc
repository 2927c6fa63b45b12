// The bucket-grid Euclidean clustering must give exactly the clusters of PCL's kd-tree path:
// same clusters, same points in the same order, on simulated Kinect frames, lattice clouds whose
// neighbours sit at exactly the tolerance, and random blobs.
#include <algorithm>
#include <functional>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "tests/sanitizer_build.h"

#include "core/depth/cluster_extractor.h"
#include "core/depth/depth_to_cloud.h"
#include "core/depth/grid_euclidean_clusters.h"
#include "core/sim/frame_simulator.h"

namespace hpose {
namespace {

// Runs both methods and requires identical output. Returns the number of clusters.
size_t ExpectSameClusters(const PointCloud& cloud, const FloorEstimate& floor,
                          ClusterOptions options, const std::string& what) {
  options.method = ClusterOptions::Method::kPcl;
  const Result<std::vector<Cluster>> reference = ExtractClusters(cloud, floor, options);
  options.method = ClusterOptions::Method::kGrid;
  const Result<std::vector<Cluster>> grid = ExtractClusters(cloud, floor, options);
  EXPECT_TRUE(reference.ok() && grid.ok()) << what;
  if (!reference.ok() || !grid.ok()) return 0;
  EXPECT_EQ(grid->size(), reference->size()) << what;
  for (size_t c = 0; c < std::min(grid->size(), reference->size()); ++c) {
    const Cluster& g = (*grid)[c];
    const Cluster& r = (*reference)[c];
    EXPECT_EQ(g.points.size(), r.points.size()) << what << " cluster " << c;
    EXPECT_TRUE(g.points == r.points) << what << " cluster " << c << ": different points";
    EXPECT_EQ(g.centroid, r.centroid) << what;
    EXPECT_EQ(g.min, r.min) << what;
    EXPECT_EQ(g.max, r.max) << what;
  }
  return reference->size();
}

TEST(GridClusteringTest, SameClustersAsPclOnSimulatedFrames) {
  size_t total = 0;
  const int frames = testing::kSanitizerBuild ? 3 : 10;
  for (int i = 0; i < frames; ++i) {
    FrameSpec spec;
    spec.preset = i % 2 == 0 ? "standing" : "right_arm_raised";
    spec.humanoid_pose = Pose2D{0.9 + 0.25 * (i % 5), -0.3 + 0.07 * i, 0.6 * i};
    spec.clutter = 2 + i % 5;
    spec.seed = 100 + i;
    spec.sensor_pitch_rad = 0.05 * (i % 3);
    const Result<SimulatedFrame> frame = SimulateFrame(spec);
    ASSERT_TRUE(frame.ok()) << frame.error().ToString();
    for (const bool organised : {false, true}) {
      DepthToCloudOptions cloud_options;
      cloud_options.keep_organised = organised;
      cloud_options.stride = 1 + i % 2;
      const Result<PointCloud> cloud = DepthToCloud(frame->depth, spec.intrinsics, cloud_options);
      ASSERT_TRUE(cloud.ok());
      ClusterOptions options;
      total += ExpectSameClusters(*cloud, frame->sensor_mount, options, "default");
      options.tolerance_m = 0.02 + 0.01 * (i % 4);
      options.downsample_leaf_m = i % 3 == 0 ? 0.0 : 0.008;
      options.min_points = 20;
      options.split_min_top_separation_m = 0.2;
      total += ExpectSameClusters(*cloud, frame->sensor_mount, options, "variant");
    }
  }
  EXPECT_GT(total, 4u * frames);  // the scenes really have objects on the floor.
}

// Points at the centres of a 2 cm lattice with a 4 cm tolerance: the coarse grid keeps them as
// they are, and lattice neighbours two cells apart lie at the tolerance itself, where only the
// exact comparison (squared float distance < float(tolerance^2)) decides.
TEST(GridClusteringTest, SameClustersAsPclAtExactlyTheTolerance) {
  std::mt19937 rng(7);
  for (int scene = 0; scene < (testing::kSanitizerBuild ? 3 : 12); ++scene) {
    std::bernoulli_distribution keep(0.25 + 0.05 * (scene % 6));
    PointCloud cloud;  // sensor frame = ground frame (identity floor).
    const float leaf = 0.02f;
    for (int x = 40; x < 100; ++x) {
      for (int y = -30; y < 30; ++y) {
        for (int z = 3; z < 30; ++z) {
          if (keep(rng))
            cloud.points.emplace_back((x + 0.5f) * leaf, (y + 0.5f) * leaf, (z + 0.5f) * leaf);
        }
      }
    }
    ClusterOptions options;
    options.tolerance_m = 2 * leaf;
    options.downsample_leaf_m = 0.0;
    options.min_points = 1;
    options.min_height_m = 0.0;
    options.max_footprint_m = 10.0;
    options.split_min_top_separation_m = 0.0;
    ExpectSameClusters(cloud, FloorEstimate(), options, "lattice " + std::to_string(scene));
  }
}

// The connected components of "squared float distance below the squared tolerance", numbered by
// their lowest index, from a brute-force pass over all pairs.
std::vector<int> BruteForceLabels(const std::vector<Eigen::Vector3f>& points, double tolerance,
                                  int* count) {
  const int n = static_cast<int>(points.size());
  std::vector<int> parent(n);
  for (int i = 0; i < n; ++i) parent[i] = i;
  std::function<int(int)> find = [&](int i) {
    return parent[i] == i ? i : parent[i] = find(parent[i]);
  };
  const float tol2 = static_cast<float>(tolerance * tolerance);
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      float d = 0.0f;
      for (int a = 0; a < 3; ++a) {
        const float t = points[i][a] - points[j][a];
        d += t * t;
      }
      if (d < tol2) {
        const int ri = find(i), rj = find(j);
        parent[std::max(ri, rj)] = std::min(ri, rj);
      }
    }
  }
  std::vector<int> expected(n, -1);
  *count = 0;
  for (int i = 0; i < n; ++i) {
    const int r = find(i);
    expected[i] = r == i ? (*count)++ : expected[r];
  }
  return expected;
}

// Every form of the distance tests (sixteen at a time with AVX-512 or AVX2 where the CPU has
// them, and one by one) against the brute force.
void ExpectBruteForceLabels(const std::vector<Eigen::Vector3f>& points, double tolerance,
                            const std::string& what) {
  int expected_count = 0;
  const std::vector<int> expected = BruteForceLabels(points, tolerance, &expected_count);
  int count = 0;
  EXPECT_EQ(GridEuclideanClusterLabels(points, tolerance, &count), expected) << what;
  EXPECT_EQ(count, expected_count) << what;
  count = 0;
  EXPECT_EQ(GridEuclideanClusterLabelsScalar(points, tolerance, &count), expected) << what;
  EXPECT_EQ(count, expected_count) << what;
  if (GridEuclideanClustersAvx2Available()) {
    count = 0;
    EXPECT_EQ(GridEuclideanClusterLabelsAvx2(points, tolerance, &count), expected) << what;
    EXPECT_EQ(count, expected_count) << what;
  }
  EXPECT_GT(expected_count, 1) << what;
  EXPECT_LT(expected_count, static_cast<int>(points.size())) << what;
}

TEST(GridClusteringTest, LabelsEqualBruteForceComponents) {
  std::mt19937 rng(3);
  for (int scene = 0; scene < 20; ++scene) {
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    std::vector<Eigen::Vector3f> points;
    const int n = 300 + 40 * scene;
    const float spread = 0.1f + 0.05f * (scene % 8);
    for (int i = 0; i < n; ++i)
      points.emplace_back(spread * u(rng), spread * u(rng), spread * u(rng));
    const double tolerance = spread * (0.1 + 0.03 * (scene % 5));
    ExpectBruteForceLabels(points, tolerance, "scene " + std::to_string(scene));
  }
}

// Clumps of up to 60 points, each within a bucket or two (more than the sixteen distances tested
// at a time), in rows whose gaps lie about one tolerance apart: some clumps join, some do not.
TEST(GridClusteringTest, CrowdedBucketsEqualBruteForceComponents) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::uniform_int_distribution<int> size(1, 60);
  for (int scene = 0; scene < 8; ++scene) {
    const double tolerance = 0.04;
    std::vector<Eigen::Vector3f> points;
    const float radius = 0.004f + 0.002f * scene;
    // Centres a tolerance apart plus twice the radius, give or take a centimetre.
    std::uniform_real_distribution<float> gap(0.03f, 0.05f);
    Eigen::Vector3f centre = Eigen::Vector3f::Zero();
    for (int clump = 0; clump < 30; ++clump) {
      centre.x() += gap(rng) + 2.0f * radius;
      if (clump % 6 == 0) centre = Eigen::Vector3f(0.0f, centre.y() + 0.2f, 0.0f);
      for (int k = size(rng); k > 0; --k) {
        points.push_back(centre + radius * Eigen::Vector3f(u(rng), u(rng), u(rng)));
      }
    }
    ExpectBruteForceLabels(points, tolerance, "scene " + std::to_string(scene));
  }
}

// Two balls of 30 points more than a tolerance apart, in neighbouring buckets, joined only by one
// point of the second ball's bucket that comes after all of that ball's (so beyond the first
// sixteen distances tested at a time): one cluster.
TEST(GridClusteringTest, ABridgeBeyondTheSixteenthPointOfABucketJoins) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(-0.002f, 0.002f);
  std::vector<Eigen::Vector3f> points;
  for (const float x : {0.01f, 0.075f}) {  // buckets [0, 4) cm and [4, 8) cm.
    for (int k = 0; k < 30; ++k) points.emplace_back(x + u(rng), 0.02f + u(rng), 0.02f + u(rng));
  }
  points.emplace_back(0.045f, 0.02f, 0.02f);  // within 4 cm of both balls.
  const std::vector<int> one(points.size(), 0);
  int count = 0;
  EXPECT_EQ(GridEuclideanClusterLabels(points, 0.04, &count), one);
  EXPECT_EQ(count, 1);
  count = 0;
  EXPECT_EQ(GridEuclideanClusterLabelsScalar(points, 0.04, &count), one);
  EXPECT_EQ(count, 1);
  if (GridEuclideanClustersAvx2Available()) {
    count = 0;
    EXPECT_EQ(GridEuclideanClusterLabelsAvx2(points, 0.04, &count), one);
    EXPECT_EQ(count, 1);
  }
  // Without the bridge, two.
  points.pop_back();
  GridEuclideanClusterLabels(points, 0.04, &count);
  EXPECT_EQ(count, 2);
}

// One bucket (4 cm cells) holding two groups of eight at opposite corners, more than a tolerance
// apart (the second group in lanes 8 to 15 of the sixteen distances tested at a time), and a
// point in the bucket before it close to the second group only: it joins that group, not the
// first (a distance test that reported a lane as another would join them).
TEST(GridClusteringTest, APointJoinsTheGroupOfItsOwnLanes) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<float> u(-0.001f, 0.001f);
  std::vector<Eigen::Vector3f> points;
  for (int k = 0; k < 8; ++k)
    points.emplace_back(0.035f + u(rng), 0.002f + u(rng), 0.002f + u(rng));
  for (int k = 0; k < 8; ++k)
    points.emplace_back(0.005f + u(rng), 0.038f + u(rng), 0.038f + u(rng));
  points.emplace_back(-0.005f, 0.038f, 0.038f);
  ExpectBruteForceLabels(points, 0.04, "two groups in one bucket");
}

TEST(GridClusteringTest, EmptyInputHasNoClusters) {
  int count = -1;
  EXPECT_TRUE(GridEuclideanClusterLabels({}, 0.04, &count).empty());
  EXPECT_EQ(count, 0);
}

}  // namespace
}  // namespace hpose
