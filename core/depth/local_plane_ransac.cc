#include "core/depth/local_plane_ransac.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

#include <Eigen/Geometry>

#include "core/depth/neighbour_sampler.h"

namespace hpose {
namespace {

// The points as three arrays, so that counting a hypothesis's inliers vectorises.
struct PointColumns {
  explicit PointColumns(const std::vector<Eigen::Vector3f>& points) {
    xs.reserve(points.size());
    ys.reserve(points.size());
    zs.reserve(points.size());
    for (const Eigen::Vector3f& p : points) {
      xs.push_back(p.x());
      ys.push_back(p.y());
      zs.push_back(p.z());
    }
  }
  int CountWithin(const Eigen::Vector4f& plane, float band) const {
    const float a = plane[0], b = plane[1], c = plane[2], d = plane[3];
    int count = 0;
    const size_t n = xs.size();
    for (size_t i = 0; i < n; ++i) {
      count += std::abs(a * xs[i] + b * ys[i] + c * zs[i] + d) <= band ? 1 : 0;
    }
    return count;
  }
  std::vector<float> xs, ys, zs;
};

// Hypotheses to draw so that, with probability `probability`, one of them has three inliers
// when a fraction w of the points are (at most `cap`).
double IterationsNeeded(double w, double probability, double cap) {
  const double eps = std::numeric_limits<double>::epsilon();
  const double miss = std::clamp(1.0 - w * w * w, eps, 1.0 - eps);
  return std::min(cap, std::log(1.0 - probability) / std::log(miss));
}

}  // namespace

LocalPlaneRansacResult FitPlaneLocalRansac(const std::vector<Eigen::Vector3f>& points,
                                           const LocalPlaneRansacOptions& options) {
  LocalPlaneRansacResult result;
  const int n = static_cast<int>(points.size());
  if (n < 3 || options.max_iterations < 1) return result;
  NeighbourSampler sampler(points, static_cast<float>(options.sample_radius_m));
  const PointColumns columns(points);
  const Eigen::Vector3f axis = options.axis.normalized();
  const float cos_max = static_cast<float>(std::cos(options.max_axis_angle_rad));
  const float band = static_cast<float>(options.distance_threshold_m);
  const double probability = std::clamp(options.probability, 0.0, 1.0 - 1e-12);
  std::mt19937 rng(options.seed);

  double needed = options.max_iterations;
  const int max_skipped = 10 * options.max_iterations;  // draws without a plane.
  int skipped = 0;
  int drawn = 0;
  while (drawn < needed && skipped < max_skipped) {
    const int i0 = static_cast<int>(rng() % static_cast<std::uint32_t>(n));
    int i1 = 0, i2 = 0;
    if (!sampler.DrawPair(i0, &rng, &i1, &i2)) {
      ++skipped;
      continue;
    }
    const Eigen::Vector3f& p0 = points[i0];
    const Eigen::Vector3f normal = (points[i1] - p0).cross(points[i2] - p0);
    const float norm = normal.norm();
    if (!(norm >= Eigen::NumTraits<float>::dummy_precision())) {  // collinear.
      ++skipped;
      continue;
    }
    ++drawn;
    const Eigen::Vector3f unit = normal / norm;
    if (std::abs(unit.dot(axis)) < cos_max) continue;  // too steep for the axis.
    const Eigen::Vector4f plane(unit.x(), unit.y(), unit.z(), -unit.dot(p0));
    ++result.hypotheses;
    const int count = columns.CountWithin(plane, band);
    if (count > result.inliers) {
      result.found = true;
      result.inliers = count;
      result.plane = plane;
      needed =
          IterationsNeeded(static_cast<double>(count) / n, probability, options.max_iterations);
    }
  }
  return result;
}

}  // namespace hpose
