#include "server/live_scene.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <set>
#include <unordered_set>

#include "core/depth/depth_to_cloud.h"

namespace hpose::server {

namespace {

using Clock = std::chrono::steady_clock;

// Millimetre rounding keeps the JSON short; the view draws at centimetres at best.
double Mm(double v) { return std::round(v * 1000.0) / 1000.0; }

std::uint64_t CellKey(double x, double y, double cell) {
  const auto ix = static_cast<std::int64_t>(std::floor(x / cell)) + (1 << 20);
  const auto iy = static_cast<std::int64_t>(std::floor(y / cell)) + (1 << 20);
  return (static_cast<std::uint64_t>(ix) << 32) ^ static_cast<std::uint64_t>(iy);
}

}  // namespace

std::vector<float> FloorCutPoints(const Frame& frame, const FloorEstimate& floor,
                                  const LiveSceneOptions& options) {
  PointCloud sampled;
  const PointCloud* cloud = &frame.cloud;
  if (!frame.is_cloud) {
    DepthToCloudOptions to_cloud;
    const double pixels = static_cast<double>(frame.depth.width) * frame.depth.height;
    to_cloud.stride = std::max(
        1, static_cast<int>(std::ceil(std::sqrt(pixels / std::max(1, options.max_pixels)))));
    Result<PointCloud> made = DepthToCloud(frame.depth, frame.intrinsics, to_cloud);
    if (!made.ok()) return {};
    sampled = std::move(*made);
    cloud = &sampled;
  }
  const size_t step =
      std::max<size_t>(1, cloud->size() / static_cast<size_t>(std::max(1, options.max_pixels)));
  std::vector<Eigen::Vector3d> kept;
  for (size_t i = 0; i < cloud->size(); i += step) {
    const Eigen::Vector3f& p = cloud->points[i];
    if (!p.allFinite()) continue;
    const Eigen::Vector3d g = floor.ground_from_sensor * p.cast<double>();
    if (g.z() < options.min_height_m || g.z() > options.max_height_m) continue;
    kept.push_back(g);
  }
  // Nearest first, so that a cap drops the far background rather than the robot.
  std::sort(kept.begin(), kept.end(), [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return a.head<2>().squaredNorm() < b.head<2>().squaredNorm();
  });
  std::unordered_set<std::uint64_t> cells;
  std::vector<float> out;
  for (const Eigen::Vector3d& g : kept) {
    if (out.size() / 2 >= static_cast<size_t>(options.max_points)) break;
    if (!cells.insert(CellKey(g.x(), g.y(), options.point_spacing_m)).second) continue;
    out.push_back(static_cast<float>(g.x()));
    out.push_back(static_cast<float>(g.y()));
  }
  return out;
}

LiveScene::LiveScene(const std::vector<VoxelTemplate>& templates, LiveSceneOptions options)
    : options_(options) {
  for (const VoxelTemplate& t : templates) {
    std::set<std::pair<float, float>> columns;
    for (const Eigen::Vector3f& v : t.voxels) columns.insert({v.x(), v.y()});
    footprints_[t.name].assign(columns.begin(), columns.end());
    voxel_sizes_[t.name] = t.resolution_m;
  }
}

void LiveScene::Update(const PublishedEstimate& e, const Frame& frame) {
  std::vector<float> points;
  std::vector<float> voxels;
  std::string template_name;
  bool is_humanoid = false;
  Pose2D pose;
  if (e.ok) {
    points = FloorCutPoints(frame, e.estimate.floor, options_);
    if (!e.estimate.detections.empty()) {
      const Detection& best = e.estimate.detections.front();
      template_name = best.best.template_name;
      is_humanoid = best.is_humanoid;
      pose = best.best.pose;
      const auto it = footprints_.find(template_name);
      if (it != footprints_.end()) {
        const double c = std::cos(pose.theta), s = std::sin(pose.theta);
        for (const auto& [x, y] : it->second) {
          voxels.push_back(static_cast<float>(pose.x + c * x - s * y));
          voxels.push_back(static_cast<float>(pose.y + s * x + c * y));
        }
      }
    }
  }
  const Clock::time_point now = Clock::now();
  std::lock_guard<std::mutex> lock(mu_);
  if (e.source_epoch != epoch_) trail_.clear();  // a recording looped: a new trail.
  epoch_ = e.source_epoch;
  publish_id_ = e.publish_id;
  sequence_ = e.sequence;
  points_ = std::move(points);
  voxels_ = std::move(voxels);
  template_name_ = std::move(template_name);
  is_humanoid_ = is_humanoid;
  if (is_humanoid) trail_.push_back({now, pose.x, pose.y, pose.theta});
  while (!trail_.empty() &&
         std::chrono::duration<double>(now - trail_.front().t).count() > options_.trail_s) {
    trail_.pop_front();
  }
}

std::uint64_t LiveScene::publish_id() const {
  std::lock_guard<std::mutex> lock(mu_);
  return publish_id_;
}

std::string LiveScene::Json() const {
  const Clock::time_point now = Clock::now();
  std::lock_guard<std::mutex> lock(mu_);
  nlohmann::json out;
  out["publish_id"] = publish_id_;
  out["sequence"] = sequence_;
  nlohmann::json points = nlohmann::json::array();
  for (const float v : points_) points.push_back(Mm(v));
  out["points"] = std::move(points);
  out["point_spacing"] = options_.point_spacing_m;
  out["template"] = template_name_;
  const auto size = voxel_sizes_.find(template_name_);
  out["voxel_size"] = size == voxel_sizes_.end() ? 0.0 : size->second;
  nlohmann::json voxels = nlohmann::json::array();
  for (const float v : voxels_) voxels.push_back(Mm(v));
  out["voxels"] = std::move(voxels);
  out["is_humanoid"] = is_humanoid_;
  nlohmann::json trail = nlohmann::json::array();
  for (const TrailPoint& p : trail_) {
    trail.push_back(
        {Mm(p.x), Mm(p.y), Mm(p.theta), Mm(std::chrono::duration<double>(now - p.t).count())});
  }
  out["trail"] = std::move(trail);
  return out.dump();
}

}  // namespace hpose::server
