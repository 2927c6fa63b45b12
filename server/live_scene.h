#ifndef HPOSE_SERVER_LIVE_SCENE_H_
#define HPOSE_SERVER_LIVE_SCENE_H_

#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "core/depth/cluster_extractor.h"
#include "core/templates/voxel_template.h"
#include "server/frame.h"
#include "server/pose_pipeline.h"

namespace hpose::server {

struct LiveSceneOptions {
  double point_spacing_m = 0.03;  // floor-cut points are thinned to one per cell of this edge.
  int max_points = 4000;          // at most this many points per frame (nearest kept first).
  int max_pixels = 40000;         // depth frames are sampled with a stride to about this many.
  double trail_s = 10.0;          // how long the trail of poses reaches back, seconds.
  // The floor cut: points between these heights above the floor (ClusterOptions' band).
  double min_height_m = 0.04;
  double max_height_m = 2.5;
};

// What the web view draws from above, in the ground frame (metres, radians), for the newest
// depth estimate: the frame's floor-cut points (thinned), the footprint of the best match's
// template voxels placed at its pose, and the trail of recent humanoid poses. Fed on the
// estimation thread (Update), read by HTTP handlers (Json). Thread-safe.
class LiveScene {
 public:
  LiveScene(const std::vector<VoxelTemplate>& templates, LiveSceneOptions options);

  // Rebuilds the scene from a published depth estimate and the frame it came from.
  void Update(const PublishedEstimate& e, const Frame& frame);

  // The newest scene as one JSON object (docs/WEB.md): {"publish_id", "sequence", "points":
  // [x0, y0, x1, y1, ...], "point_spacing", "template", "voxel_size", "voxels": [x0, y0, ...],
  // "is_humanoid", "trail": [[x, y, theta, age_s], ...]}; publish_id 0 before the first.
  std::string Json() const;
  std::uint64_t publish_id() const;

 private:
  struct TrailPoint {
    std::chrono::steady_clock::time_point t;
    double x, y, theta;
  };

  const LiveSceneOptions options_;
  // Per template name: the (x, y) centres of its occupied voxel columns, template frame.
  std::map<std::string, std::vector<std::pair<float, float>>> footprints_;
  std::map<std::string, double> voxel_sizes_;

  mutable std::mutex mu_;  // guards the members below.
  std::uint64_t publish_id_ = 0;
  std::uint64_t sequence_ = 0;
  std::uint64_t epoch_ = 0;
  std::vector<float> points_;  // x0, y0, x1, y1, ...
  std::string template_name_;
  bool is_humanoid_ = false;
  std::vector<float> voxels_;
  std::deque<TrailPoint> trail_;
};

// The floor-cut points of `frame` in the ground frame of `floor` (x, y pairs), thinned to one
// per `options.point_spacing_m` cell, at most options.max_points (the nearest to the sensor
// first). Exposed for tests.
std::vector<float> FloorCutPoints(const Frame& frame, const FloorEstimate& floor,
                                  const LiveSceneOptions& options);

}  // namespace hpose::server

#endif  // HPOSE_SERVER_LIVE_SCENE_H_
