#include "core/depth/floor_plane.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

namespace hpose {

bool FitFloorPlaneLeastSquares(const std::vector<Eigen::Vector3f>& points,
                               const std::vector<int>& indices, double threshold_m,
                               Eigen::Vector4d* plane) {
  if (indices.size() < 3) return false;
  const double base_var = 0.25 * threshold_m * threshold_m;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  double weight_sum = 0.0;
  for (const int i : indices) {
    const Eigen::Vector3d p = points[i].cast<double>();
    const double range_sigma = kFloorDepthNoisePerM2 * p.squaredNorm();
    const double w = 1.0 / (base_var + range_sigma * range_sigma);
    mean += w * p;
    second.noalias() += w * p * p.transpose();
    weight_sum += w;
  }
  mean /= weight_sum;
  const Eigen::Matrix3d cov = second / weight_sum - mean * mean.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(cov);
  if (solver.info() != Eigen::Success) return false;
  Eigen::Vector3d n = solver.eigenvectors().col(0);  // eigenvalues ascend.
  if (!n.allFinite() || n.norm() < 1e-9) return false;
  n.normalize();
  double d = -n.dot(mean);
  if (d < 0.0) {
    n = -n;
    d = -d;
  }
  *plane << n, d;
  return true;
}

void SelectFloorInliers(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector4d& plane,
                        double threshold_m, std::vector<int>* inliers) {
  inliers->clear();
  const Eigen::Vector3f n = plane.head<3>().cast<float>();
  const float d = static_cast<float>(plane[3]);
  const float t = static_cast<float>(threshold_m);
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    if (std::abs(n.dot(p) + d) <= FloorInlierBand(t, p.squaredNorm())) {
      inliers->push_back(static_cast<int>(i));
    }
  }
}

size_t CountBelowFloorPlane(const std::vector<Eigen::Vector3f>& points,
                            const Eigen::Vector4d& plane, double threshold_m) {
  const Eigen::Vector3f n = plane.head<3>().cast<float>();
  const float d = static_cast<float>(plane[3]);
  const float t = static_cast<float>(threshold_m);
  size_t below = 0;
  for (const Eigen::Vector3f& p : points) {
    if (n.dot(p) + d < -(2.0f * FloorInlierBand(t, p.squaredNorm()) + 0.03f)) ++below;
  }
  return below;
}

double FloorInlierWidth(const std::vector<Eigen::Vector3f>& points, const std::vector<int>& indices,
                        const Eigen::Vector4d& plane) {
  if (indices.size() < 3) return 0.0;
  const Eigen::Vector3d normal = plane.head<3>().normalized();
  const Eigen::Vector3d u = normal.unitOrthogonal();
  const Eigen::Vector3d v = normal.cross(u);
  std::vector<Eigen::Vector2d> in_plane;
  in_plane.reserve(indices.size());
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const int i : indices) {
    const Eigen::Vector3d p = points[i].cast<double>();
    in_plane.emplace_back(u.dot(p), v.dot(p));
    mean += in_plane.back();
  }
  mean /= static_cast<double>(in_plane.size());
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const Eigen::Vector2d& q : in_plane) scatter += (q - mean) * (q - mean).transpose();
  // The eigenvector of the smaller eigenvalue (SelfAdjointEigenSolver sorts them ascending).
  const Eigen::Vector2d minor =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(scatter).eigenvectors().col(0);
  std::vector<double> offsets;
  offsets.reserve(in_plane.size());
  for (const Eigen::Vector2d& q : in_plane) offsets.push_back(minor.dot(q));
  const size_t lo = offsets.size() * 5 / 100, hi = offsets.size() * 95 / 100;
  std::nth_element(offsets.begin(), offsets.begin() + lo, offsets.end());
  const double low = offsets[lo];
  std::nth_element(offsets.begin(), offsets.begin() + hi, offsets.end());
  return offsets[hi] - low;
}

}  // namespace hpose
