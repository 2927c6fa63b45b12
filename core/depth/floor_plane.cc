#include "core/depth/floor_plane.h"

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

}  // namespace hpose
