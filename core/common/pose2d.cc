#include "core/common/pose2d.h"

namespace hpose {

double NormalizeAngle(double rad) {
  double a = std::fmod(rad, 2.0 * kPi);
  if (a <= -kPi) a += 2.0 * kPi;
  if (a > kPi) a -= 2.0 * kPi;
  return a;
}

Eigen::Isometry3d Pose2D::ToIsometry() const {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  t.translation() = Eigen::Vector3d(x, y, 0.0);
  return t;
}

}  // namespace hpose
