#ifndef HPOSE_CORE_COMMON_POSE2D_H_
#define HPOSE_CORE_COMMON_POSE2D_H_

#include <cmath>

#include <Eigen/Geometry>

namespace hpose {

constexpr double kPi = 3.14159265358979323846;

inline double DegToRad(double deg) { return deg * kPi / 180.0; }
inline double RadToDeg(double rad) { return rad * 180.0 / kPi; }

// Wraps an angle to (-pi, pi].
double NormalizeAngle(double rad);

// Signed smallest difference a - b, in (-pi, pi].
inline double AngleDiff(double a, double b) { return NormalizeAngle(a - b); }

// A pose on the floor: the robot (template) frame expressed in the ground frame.
// x, y in metres; theta in radians, counter-clockwise about +z, in (-pi, pi].
struct Pose2D {
  double x = 0.0;
  double y = 0.0;
  double theta = 0.0;

  // ground_from_robot as a 3D rigid transform (rotation about z, no z offset).
  Eigen::Isometry3d ToIsometry() const;
};

}  // namespace hpose

#endif  // HPOSE_CORE_COMMON_POSE2D_H_
