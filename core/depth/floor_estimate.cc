#include "core/depth/floor_estimate.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace hpose {

FloorEstimate FloorEstimate::FromPlane(const Eigen::Vector4d& plane_sensor) {
  Eigen::Vector3d n = plane_sensor.head<3>();
  double d = plane_sensor[3];
  const double norm = n.norm();
  assert(norm > 0.0);
  n /= norm;
  d /= norm;
  // Orient the normal towards the sensor: the optical centre (origin) lies above the floor.
  if (d < 0.0) {
    n = -n;
    d = -d;
  }
  const Eigen::Vector3d z_axis = n;
  Eigen::Vector3d x_axis = Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitZ().dot(n) * n;
  assert(x_axis.norm() > 1e-9);
  x_axis.normalize();
  const Eigen::Vector3d y_axis = z_axis.cross(x_axis);

  FloorEstimate floor;
  floor.plane_sensor << n, d;
  Eigen::Matrix3d r;
  r.row(0) = x_axis.transpose();
  r.row(1) = y_axis.transpose();
  r.row(2) = z_axis.transpose();
  const Eigen::Vector3d origin_sensor = -d * n;  // foot of the optical centre on the floor.
  floor.ground_from_sensor.linear() = r;
  floor.ground_from_sensor.translation() = -r * origin_sensor;
  floor.height_m = d;
  floor.pitch_rad = std::asin(std::clamp(-n.z(), -1.0, 1.0));
  floor.roll_rad = std::atan2(-n.x(), -n.y());
  return floor;
}

FloorEstimate FloorEstimate::FromHeightPitchRoll(double height_m, double pitch_rad,
                                                 double roll_rad) {
  const Eigen::Vector3d n(-std::sin(roll_rad) * std::cos(pitch_rad),
                          -std::cos(roll_rad) * std::cos(pitch_rad), -std::sin(pitch_rad));
  Eigen::Vector4d plane;
  plane << n, height_m;
  FloorEstimate floor = FromPlane(plane);
  floor.fitted = false;
  return floor;
}

}  // namespace hpose
