#include "tests/depth/synthetic_scene.h"

#include <cmath>
#include <limits>
#include <random>

namespace hpose {
namespace testing_scene {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double HitPlane(const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  if (std::abs(d.z()) < 1e-12) return kInf;
  const double t = -o.z() / d.z();
  return t > 0.0 ? t : kInf;
}

double HitBox(const Box& box, const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  double t_near = -kInf;
  double t_far = kInf;
  for (int a = 0; a < 3; ++a) {
    if (std::abs(d[a]) < 1e-12) {
      if (o[a] < box.min[a] || o[a] > box.max[a]) return kInf;
      continue;
    }
    double t0 = (box.min[a] - o[a]) / d[a];
    double t1 = (box.max[a] - o[a]) / d[a];
    if (t0 > t1) std::swap(t0, t1);
    t_near = std::max(t_near, t0);
    t_far = std::min(t_far, t1);
  }
  if (t_near > t_far || t_far <= 0.0) return kInf;
  return t_near > 0.0 ? t_near : kInf;
}

double HitCylinder(const Cylinder& c, const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  // Side: |(o + t d)_xy - c|^2 = r^2.
  const double ox = o.x() - c.x;
  const double oy = o.y() - c.y;
  const double a = d.x() * d.x() + d.y() * d.y();
  double best = kInf;
  if (a > 1e-12) {
    const double b = 2.0 * (ox * d.x() + oy * d.y());
    const double cc = ox * ox + oy * oy - c.radius * c.radius;
    const double disc = b * b - 4.0 * a * cc;
    if (disc >= 0.0) {
      const double t = (-b - std::sqrt(disc)) / (2.0 * a);
      const double z = o.z() + t * d.z();
      if (t > 0.0 && z >= 0.0 && z <= c.height) best = t;
    }
  }
  // Top cap.
  if (std::abs(d.z()) > 1e-12) {
    const double t = (c.height - o.z()) / d.z();
    if (t > 0.0 && t < best) {
      const double px = ox + t * d.x();
      const double py = oy + t * d.y();
      if (px * px + py * py <= c.radius * c.radius) best = t;
    }
  }
  return best;
}

}  // namespace

Eigen::Isometry3d GroundFromSensor(double height_m, double pitch_rad, double roll_rad) {
  const Eigen::Vector3d xg = Eigen::Vector3d::UnitX();
  const Eigen::Vector3d zg = Eigen::Vector3d::UnitZ();
  const double cp = std::cos(pitch_rad), sp = std::sin(pitch_rad);
  const Eigen::Vector3d z_s = cp * xg - sp * zg;   // optical axis, tilted down.
  const Eigen::Vector3d y_s = -cp * zg - sp * xg;  // image down.
  const Eigen::Vector3d x_s = y_s.cross(z_s);      // image right.
  const double cr = std::cos(roll_rad), sr = std::sin(roll_rad);
  const Eigen::Vector3d x_r = cr * x_s + sr * y_s;  // right side goes down for roll > 0.
  const Eigen::Vector3d y_r = -sr * x_s + cr * y_s;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear().col(0) = x_r;
  pose.linear().col(1) = y_r;
  pose.linear().col(2) = z_s;
  pose.translation() = Eigen::Vector3d(0.0, 0.0, height_m);
  return pose;
}

PointCloud Render(const Scene& scene, const Eigen::Isometry3d& ground_from_sensor,
                  const Intrinsics& k, const RenderOptions& options) {
  std::mt19937 rng(options.seed);
  std::normal_distribution<double> unit(0.0, 1.0);
  const Eigen::Vector3d origin = ground_from_sensor.translation();
  const Eigen::Matrix3d rotation = ground_from_sensor.linear();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  PointCloud cloud;
  if (options.organised) {
    cloud.width = k.width;
    cloud.height = k.height;
  }
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const Eigen::Vector3d ray_sensor((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);
      const Eigen::Vector3d dir = rotation * ray_sensor;  // unnormalised: t is depth z.
      double t = scene.floor ? HitPlane(origin, dir) : kInf;
      for (const Box& box : scene.boxes) t = std::min(t, HitBox(box, origin, dir));
      for (const Cylinder& c : scene.cylinders) t = std::min(t, HitCylinder(c, origin, dir));
      if (!(t < kInf) || t * ray_sensor.norm() > options.max_range_m) {
        if (options.organised) cloud.points.emplace_back(nan, nan, nan);
        continue;
      }
      double z = t;
      if (options.noise_sigma_k > 0.0) z += options.noise_sigma_k * z * z * unit(rng);
      cloud.points.push_back((ray_sensor * z).cast<float>());
    }
  }
  return cloud;
}

}  // namespace testing_scene
}  // namespace hpose
