#include "core/search/surface_model.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include <Eigen/Eigenvalues>

namespace hpose {
namespace {

// Hash of an integer cell for neighbour look-ups while building.
struct CellHash {
  size_t operator()(const Eigen::Vector3i& c) const {
    return static_cast<size_t>(c.x()) * 73856093u ^ static_cast<size_t>(c.y()) * 19349663u ^
           static_cast<size_t>(c.z()) * 83492791u;
  }
};

using CellMap = std::unordered_map<Eigen::Vector3i, std::vector<int>, CellHash>;

Eigen::Vector3i CellIndex(const Eigen::Vector3f& p, float inv) {
  return Eigen::Vector3i(static_cast<int>(std::floor(p.x() * inv)),
                         static_cast<int>(std::floor(p.y() * inv)),
                         static_cast<int>(std::floor(p.z() * inv)));
}

// Unit normal of the plane fitted to the points within `radius` of each point (the direction of
// least spread); straight up where too few neighbours exist.
std::vector<Eigen::Vector3f> PlaneNormals(const std::vector<Eigen::Vector3f>& points,
                                          float radius) {
  const float inv = 1.0f / radius;
  CellMap cells;
  for (size_t i = 0; i < points.size(); ++i) {
    cells[CellIndex(points[i], inv)].push_back(static_cast<int>(i));
  }
  std::vector<Eigen::Vector3f> normals(points.size(), Eigen::Vector3f::UnitZ());
  const float r2 = radius * radius;
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    const Eigen::Vector3i c = CellIndex(p, inv);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
    int n = 0;
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          auto it = cells.find(c + Eigen::Vector3i(dx, dy, dz));
          if (it == cells.end()) continue;
          for (int j : it->second) {
            if ((points[j] - p).squaredNorm() > r2) continue;
            const Eigen::Vector3d q = (points[j] - p).cast<double>();
            sum += q;
            outer += q * q.transpose();
            ++n;
          }
        }
      }
    }
    if (n < 3) continue;
    const Eigen::Vector3d mean = sum / n;
    const Eigen::Matrix3d cov = outer / n - mean * mean.transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
    normals[i] = eig.eigenvectors().col(0).normalized().cast<float>();
  }
  return normals;
}

}  // namespace

SurfaceModel::SurfaceModel(const VoxelTemplate& tpl, double spacing_m)
    : points_(tpl.SurfaceOrVoxels()),
      spacing_(tpl.surface.empty() ? tpl.resolution_m : tpl.SurfaceCellM()) {
  if (!tpl.surface.empty() && spacing_m > spacing_) {
    points_ = ReduceSurfacePoints(points_, spacing_m);
    spacing_ = spacing_m;
  }
  normals_ = PlaneNormals(points_, static_cast<float>(2.5 * spacing_));
  for (const Eigen::Vector3f& p : points_) centre_ += p;
  if (!points_.empty()) centre_ /= static_cast<float>(points_.size());
  xs_.reserve(points_.size());
  ys_.reserve(points_.size());
  zs_.reserve(points_.size());
  for (const Eigen::Vector3f& p : points_) {
    xs_.push_back(p.x());
    ys_.push_back(p.y());
    zs_.push_back(p.z());
    box_lo_ = box_lo_.cwiseMin(p.cast<double>());
    box_hi_ = box_hi_.cwiseMax(p.cast<double>());
  }
}

}  // namespace hpose
