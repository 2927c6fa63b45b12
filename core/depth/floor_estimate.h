#ifndef HPOSE_CORE_DEPTH_FLOOR_ESTIMATE_H_
#define HPOSE_CORE_DEPTH_FLOOR_ESTIMATE_H_

#include <Eigen/Geometry>

namespace hpose {

// The floor and the ground frame derived from it (README, "Frames and units"): origin on the floor
// directly below the sensor's optical centre, +z up (floor normal), +x the optical axis projected
// onto the floor, +y left.
struct FloorEstimate {
  // Plane a x + b y + c z + d = 0 in the sensor frame, (a, b, c) unit, pointing up (towards the
  // sensor side of the floor), so d = sensor height above the floor in metres.
  Eigen::Vector4d plane_sensor = Eigen::Vector4d(0, -1, 0, 0);
  Eigen::Isometry3d ground_from_sensor = Eigen::Isometry3d::Identity();
  double height_m = 0.0;   // optical centre above the floor.
  double pitch_rad = 0.0;  // optical axis below the horizon is positive (looking down).
  double roll_rad = 0.0;   // rotation about the optical axis; positive = image right side down.
  int inliers = 0;         // points that supported the plane (0 for a fixed calibration).
  bool fitted = false;     // false when given as a fixed calibration.

  // Builds the ground frame from a plane in the sensor frame (normal any sign). The plane must
  // not contain the optical axis direction's projection degenerate case (normal parallel to z).
  static FloorEstimate FromPlane(const Eigen::Vector4d& plane_sensor);
  // Builds a fixed calibration from height (m), pitch and roll (rad) with the conventions above.
  static FloorEstimate FromHeightPitchRoll(double height_m, double pitch_rad, double roll_rad);
};

}  // namespace hpose

#endif  // HPOSE_CORE_DEPTH_FLOOR_ESTIMATE_H_
