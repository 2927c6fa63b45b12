#include "core/templates/capture_template.h"

#include <cmath>
#include <map>
#include <tuple>

#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <Eigen/Eigenvalues>

namespace hpose {
namespace {

using Cell = std::tuple<int, int, int>;

Cell CellTupleOf(const Eigen::Vector3f& p, double resolution_m) {
  const double inv = 1.0 / resolution_m;
  return {static_cast<int>(std::floor(inv * p.x())), static_cast<int>(std::floor(inv * p.y())),
          static_cast<int>(std::floor(inv * p.z()))};
}

std::map<Cell, int> CountCells(const std::vector<Eigen::Vector3f>& points, double resolution_m) {
  std::map<Cell, int> cells;
  for (const Eigen::Vector3f& p : points) {
    if (p.allFinite()) ++cells[CellTupleOf(p, resolution_m)];
  }
  return cells;
}

}  // namespace

Eigen::Vector2d VoxelCentroidXY(const std::vector<Eigen::Vector3f>& points, double resolution_m,
                                int min_points_per_voxel) {
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  int n = 0;
  for (const auto& [cell, count] : CountCells(points, resolution_m)) {
    if (count < min_points_per_voxel) continue;
    sum += resolution_m * Eigen::Vector2d(std::get<0>(cell) + 0.5, std::get<1>(cell) + 0.5);
    ++n;
  }
  return n > 0 ? Eigen::Vector2d(sum / n) : Eigen::Vector2d::Zero();
}

std::vector<Eigen::Vector3f> ProjectOntoLocalPlanes(const std::vector<Eigen::Vector3f>& points,
                                                    double radius_m) {
  auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  for (const Eigen::Vector3f& p : points) cloud->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;
  tree.setInputCloud(cloud);
  std::vector<Eigen::Vector3f> out = points;
  pcl::Indices idx;
  std::vector<float> d2;
  for (size_t i = 0; i < points.size(); ++i) {
    if (tree.radiusSearch((*cloud)[i], radius_m, idx, d2) < 6) continue;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const int k : idx) mean += points[k].cast<double>();
    mean /= static_cast<double>(idx.size());
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const int k : idx) {
      const Eigen::Vector3d e = points[k].cast<double>() - mean;
      cov += e * e.transpose();
    }
    const Eigen::Vector3d n =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(0);
    const Eigen::Vector3d p = points[i].cast<double>();
    out[i] = (p - n.dot(p - mean) * n).cast<float>();
  }
  return out;
}

std::vector<Eigen::Vector3f> DropSparseVoxels(const std::vector<Eigen::Vector3f>& points,
                                              double resolution_m, int min_points_per_voxel,
                                              int* dropped) {
  const std::map<Cell, int> cells = CountCells(points, resolution_m);
  if (dropped) {
    *dropped = 0;
    for (const auto& [cell, count] : cells) *dropped += count < min_points_per_voxel ? 1 : 0;
  }
  std::vector<Eigen::Vector3f> out;
  out.reserve(points.size());
  for (const Eigen::Vector3f& p : points) {
    if (!p.allFinite()) continue;
    if (cells.at(CellTupleOf(p, resolution_m)) >= min_points_per_voxel) out.push_back(p);
  }
  return out;
}

Result<CaptureTemplate> MakeCaptureTemplate(const CaptureRegistration& registration,
                                            const CaptureTemplateOptions& options) {
  if (!(options.resolution_m >= 0.001 && options.resolution_m <= 0.5)) {
    return MakeError(ErrorCode::kInvalidArgument, "template resolution must be in [1 mm, 0.5 m]");
  }
  int front = -1;
  for (size_t i = 0; i < registration.views.size(); ++i) {
    if (registration.views[i].capture_index == options.front_view) front = static_cast<int>(i);
  }
  if (front < 0) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "front view " + std::to_string(options.front_view) +
                         " is not among the registered captures (dropped or out of range)");
  }
  if (options.origin == TemplateOrigin::kAxis && registration.motion != CaptureMotion::kTurntable) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "the axis origin needs turntable captures (hand-turned views have no axis)");
  }

  CaptureTemplate out;
  std::vector<Eigen::Vector3f> merged = MergedTablePoints(registration);
  if (options.smoothing_radius_m > 0.0) {
    merged = ProjectOntoLocalPlanes(merged, options.smoothing_radius_m);
  }
  out.merged_points = static_cast<int>(merged.size());
  const std::vector<Eigen::Vector3f> kept = DropSparseVoxels(
      merged, options.resolution_m, options.min_points_per_voxel, &out.noise_voxels_dropped);

  // Origin (table frame).
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();
  if (options.origin == TemplateOrigin::kVoxelCentroid) {
    origin = VoxelCentroidXY(kept, options.resolution_m);
  }
  // +x: from the robot towards the sensor in the front view. The origin seen from that view's
  // ground frame (the sensor is above its origin), then the direction turned into the table.
  const Pose2D& t = registration.table_from_ground[front];
  const double c = std::cos(t.theta), s = std::sin(t.theta);
  const double gx = c * (origin.x() - t.x) + s * (origin.y() - t.y);
  const double gy = -s * (origin.x() - t.x) + c * (origin.y() - t.y);
  const double facing_ground = std::atan2(-gy, -gx);
  const double yaw = NormalizeAngle(facing_ground + t.theta + options.front_yaw_rad);
  out.table_from_template = Pose2D{origin.x(), origin.y(), yaw};

  const double cy = std::cos(yaw), sy = std::sin(yaw);
  std::vector<Eigen::Vector3f> points;
  points.reserve(kept.size());
  for (const Eigen::Vector3f& q : kept) {
    const double x = q.x() - origin.x(), y = q.y() - origin.y();
    points.emplace_back(static_cast<float>(cy * x + sy * y), static_cast<float>(-sy * x + cy * y),
                        q.z());
  }
  Result<VoxelTemplate> tpl = MakeTemplateFromPoints(points, options.name, options.resolution_m,
                                                     options.variant, options.source);
  if (!tpl.ok()) return tpl.error();
  out.tpl = std::move(*tpl);
  return out;
}

}  // namespace hpose
