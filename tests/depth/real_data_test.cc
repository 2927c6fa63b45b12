// The depth pipeline on real Kinect frames from the shared data directory (skipped when absent).
#include <sys/stat.h>

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/depth/cluster_extractor.h"
#include "core/depth/floor_fitter.h"
#include "core/io/cloud_io.h"

namespace hpose {
namespace {

constexpr double kDeg = M_PI / 180.0;

bool Exists(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0;
}

const std::string kFivePeople = std::string(HPOSE_SHARED_DATA_DIR) + "/kinect/five_people.pcd";

TEST(RealDataTest, FivePeopleFloorMatchesTheKnownPlane) {
  if (!Exists(kFivePeople)) GTEST_SKIP() << "shared data absent: " << kFivePeople;
  const Result<PointCloud> cloud = ReadCloud(kFivePeople);
  ASSERT_TRUE(cloud.ok()) << cloud.error().ToString();
  ASSERT_TRUE(cloud->organised());
  ASSERT_EQ(cloud->width, 640);
  ASSERT_EQ(cloud->height, 480);

  const Result<FloorEstimate> floor = FitFloor(*cloud);
  ASSERT_TRUE(floor.ok()) << floor.error().ToString();
  // Ground plane published with the data (camera frame, y down), normal pointing down.
  Eigen::Vector4d known(-0.0103586, 0.997011, 0.0765573, -1.26614);
  known /= known.head<3>().norm();
  known = -known;  // towards the sensor, as FloorEstimate stores it.
  const double angle =
      std::acos(std::clamp(floor->plane_sensor.head<3>().dot(known.head<3>()), -1.0, 1.0));
  EXPECT_LT(angle / kDeg, 2.0);
  EXPECT_NEAR(floor->height_m, known[3], 0.05);
  EXPECT_GT(floor->inliers, 0);
  EXPECT_TRUE(floor->fitted);
  // A Kinect on a tripod looking slightly down.
  EXPECT_GT(floor->pitch_rad, 0.0);
  EXPECT_LT(floor->pitch_rad, 10 * kDeg);
}

TEST(RealDataTest, FivePeopleGiveFivePersonSizedClusters) {
  if (!Exists(kFivePeople)) GTEST_SKIP() << "shared data absent: " << kFivePeople;
  const Result<PointCloud> cloud = ReadCloud(kFivePeople);
  ASSERT_TRUE(cloud.ok()) << cloud.error().ToString();
  const Result<FloorEstimate> floor = FitFloor(*cloud);
  ASSERT_TRUE(floor.ok()) << floor.error().ToString();
  const Result<std::vector<Cluster>> clusters = ExtractClusters(*cloud, *floor);
  ASSERT_TRUE(clusters.ok()) << clusters.error().ToString();
  std::vector<const Cluster*> people;
  for (const Cluster& c : *clusters) {
    if (c.height() >= 1.2f && c.height() <= 2.4f) people.push_back(&c);
  }
  ASSERT_EQ(people.size(), 5u);
  for (size_t i = 0; i < people.size(); ++i) {
    const Cluster& p = *people[i];
    // Standing people: a footprint well under a metre, in front of the sensor, legs reaching
    // down towards the floor (feet may be hidden behind someone else).
    EXPECT_LT(std::max(p.max.x() - p.min.x(), p.max.y() - p.min.y()), 0.9f);
    EXPECT_GT(p.centroid.x(), 1.0f);
    EXPECT_LT(p.min.z(), 0.4f);
    EXPECT_GT(p.centroid.z(), 0.6f);
    EXPECT_LT(p.centroid.z(), 1.3f);
    // Distinct people: centroids at least a shoulder width apart.
    for (size_t j = 0; j < i; ++j) {
      EXPECT_GT((p.centroid.head<2>() - people[j]->centroid.head<2>()).norm(), 0.3f);
    }
  }
}

TEST(RealDataTest, ConsecutiveGrabberFramesAgree) {
  const std::string dir = std::string(HPOSE_SHARED_DATA_DIR) + "/kinect/grabber_sequences/pcd/";
  const std::vector<std::string> frames = {"frame_20121214T142255.814212.pcd",
                                           "frame_20121214T142256.068683.pcd",
                                           "frame_20121214T142256.332395.pcd"};
  if (!Exists(dir + frames[0])) GTEST_SKIP() << "shared data absent: " << dir;
  std::vector<FloorEstimate> floors;
  std::vector<size_t> counts;
  for (const std::string& name : frames) {
    const Result<PointCloud> cloud = ReadCloud(dir + name);
    ASSERT_TRUE(cloud.ok()) << cloud.error().ToString();
    const Result<FloorEstimate> floor = FitFloor(*cloud);
    ASSERT_TRUE(floor.ok()) << name << ": " << floor.error().ToString();
    floors.push_back(*floor);
    const Result<std::vector<Cluster>> clusters = ExtractClusters(*cloud, *floor);
    ASSERT_TRUE(clusters.ok());
    EXPECT_FALSE(clusters->empty()) << name;
    counts.push_back(clusters->size());
  }
  // A static camera: the floor of every frame agrees with the first within noise.
  for (size_t i = 1; i < floors.size(); ++i) {
    const double angle = std::acos(std::clamp(
        floors[i].plane_sensor.head<3>().dot(floors[0].plane_sensor.head<3>()), -1.0, 1.0));
    EXPECT_LT(angle / kDeg, 1.0) << frames[i];
    EXPECT_NEAR(floors[i].height_m, floors[0].height_m, 0.02) << frames[i];
  }
  // The largest objects are the same in every frame (small ones may flicker).
  for (size_t i = 1; i < counts.size(); ++i) EXPECT_NEAR(counts[i], counts[0], 1.0);
}

}  // namespace
}  // namespace hpose
