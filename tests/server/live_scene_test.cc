#include "server/live_scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <set>

#include "core/depth/floor_estimate.h"

namespace hpose::server {
namespace {

// A level sensor 0.5 m above the floor: ground x = sensor z, y = -sensor x, z = 0.5 - sensor y.
FloorEstimate LevelFloor() { return FloorEstimate::FromHeightPitchRoll(0.5, 0.0, 0.0); }

Eigen::Vector3f SensorPoint(double gx, double gy, double gz) {
  return Eigen::Vector3f(static_cast<float>(-gy), static_cast<float>(0.5 - gz),
                         static_cast<float>(gx));
}

TEST(LiveSceneTest, FloorCutKeepsObjectsAboveTheFloorThinnedToTheSpacing) {
  Frame frame;
  frame.is_cloud = true;
  for (double x = 0.5; x < 3.0; x += 0.01) {  // the floor itself: cut away.
    for (double y = -1.0; y < 1.0; y += 0.05) frame.cloud.points.push_back(SensorPoint(x, y, 0.0));
  }
  for (double x = 1.0; x <= 1.2; x += 0.005) {  // a box 0.2 x 0.2 x 0.5 m: kept.
    for (double y = -0.1; y <= 0.1; y += 0.005) {
      for (double z = 0.1; z <= 0.6; z += 0.1) frame.cloud.points.push_back(SensorPoint(x, y, z));
    }
  }
  frame.cloud.points.push_back(SensorPoint(2.0, 0.0, 3.0));  // above the band: cut away.
  frame.cloud.points.push_back(Eigen::Vector3f(NAN, NAN, NAN));
  LiveSceneOptions options;
  options.point_spacing_m = 0.03;
  options.max_pixels = 1 << 30;  // no sampling: every point is considered.
  const std::vector<float> xy = FloorCutPoints(frame, LevelFloor(), options);
  ASSERT_FALSE(xy.empty());
  ASSERT_EQ(xy.size() % 2, 0u);
  std::set<std::pair<int, int>> cells;
  for (size_t i = 0; i < xy.size(); i += 2) {
    EXPECT_GE(xy[i], 1.0 - 1e-4);
    EXPECT_LE(xy[i], 1.2 + 1e-4);
    EXPECT_LE(std::abs(xy[i + 1]), 0.1 + 1e-4);
    const bool fresh = cells
                           .insert({static_cast<int>(std::floor(xy[i] / 0.03)),
                                    static_cast<int>(std::floor(xy[i + 1] / 0.03))})
                           .second;
    EXPECT_TRUE(fresh) << "two points in one cell at " << xy[i] << ", " << xy[i + 1];
  }
  // The box covers cells 33..40 in x and -4..3 in y: about 8 x 8 of them, each holding a point.
  EXPECT_GE(cells.size(), 40u);

  options.max_points = 10;
  EXPECT_EQ(FloorCutPoints(frame, LevelFloor(), options).size(), 20u);
}

TEST(LiveSceneTest, DepthFramesAreBackProjectedThroughTheFloor) {
  Frame frame;
  frame.intrinsics = Intrinsics::KinectV1(160, 120);
  frame.depth = DepthImage(160, 120);
  for (auto& d : frame.depth.mm) d = 1500;  // a wall 1.5 m ahead.
  LiveSceneOptions options;
  const std::vector<float> xy = FloorCutPoints(frame, LevelFloor(), options);
  ASSERT_FALSE(xy.empty());
  for (size_t i = 0; i < xy.size(); i += 2) EXPECT_NEAR(xy[i], 1.5, 1e-3);
}

TEST(LiveSceneTest, PlacesTheTemplateAtThePoseAndKeepsATrail) {
  VoxelTemplate t;
  t.name = "box";
  t.resolution_m = 0.02;
  t.voxels = {Eigen::Vector3f(0.0f, 0.0f, 0.01f), Eigen::Vector3f(0.0f, 0.0f, 0.03f),
              Eigen::Vector3f(0.1f, 0.0f, 0.01f)};
  LiveScene scene({t}, LiveSceneOptions{});
  EXPECT_EQ(nlohmann::json::parse(scene.Json())["publish_id"], 0);

  PublishedEstimate e;
  e.ok = true;
  e.publish_id = 7;
  e.sequence = 3;
  e.estimate.floor = LevelFloor();
  Detection d;
  d.best.template_name = "box";
  d.best.pose = Pose2D{1.0, 2.0, M_PI / 2};
  d.is_humanoid = true;
  e.estimate.detections.push_back(d);
  Frame frame;
  frame.is_cloud = true;
  scene.Update(e, frame);
  e.publish_id = 8;
  scene.Update(e, frame);

  const nlohmann::json j = nlohmann::json::parse(scene.Json());
  EXPECT_EQ(j["publish_id"], 8);
  EXPECT_EQ(j["template"], "box");
  EXPECT_EQ(j["voxel_size"], 0.02);
  EXPECT_TRUE(j["is_humanoid"]);
  // Two voxel columns: (0, 0) and (0.1, 0) turned 90 degrees and moved to (1, 2).
  ASSERT_EQ(j["voxels"].size(), 4u);
  EXPECT_NEAR(j["voxels"][0].get<double>(), 1.0, 1e-3);
  EXPECT_NEAR(j["voxels"][1].get<double>(), 2.0, 1e-3);
  EXPECT_NEAR(j["voxels"][2].get<double>(), 1.0, 1e-3);
  EXPECT_NEAR(j["voxels"][3].get<double>(), 2.1, 1e-3);
  ASSERT_EQ(j["trail"].size(), 2u);
  EXPECT_NEAR(j["trail"][1][2].get<double>(), M_PI / 2, 1e-3);

  e.source_epoch = 1;  // the recording looped: the trail starts over.
  scene.Update(e, frame);
  EXPECT_EQ(nlohmann::json::parse(scene.Json())["trail"].size(), 1u);
}

}  // namespace
}  // namespace hpose::server
