#ifndef HPOSE_CORE_DEPTH_FLOOR_PLANE_H_
#define HPOSE_CORE_DEPTH_FLOOR_PLANE_H_

// Plane helpers shared by the floor fit (FitFloor) and the floor tracker (FloorTracker). Points
// are in the sensor frame (metres); a plane is (unit normal, d) with the sensor (origin) on its
// positive side, d > 0.

#include <cstddef>
#include <vector>

#include <Eigen/Core>

namespace hpose {

// Depth noise of a structured-light sensor grows with the square of the range (SPEC §5,
// Kinect v1: sigma_z = 1.425e-3 * z^2). Far floor points are noisy and quantised in steps of
// several centimetres, so inlier bands widen with range and far points weigh less.
constexpr double kFloorDepthNoisePerM2 = 1.425e-3;
// The same with its disparity steps: steps of about 2.9e-3 z^2 (1/8 pixel of disparity, focal
// length 580 px, 7.5 cm baseline) are a uniform error of 0.83e-3 z^2, together with the noise
// 1.65e-3 z^2. A simulated floor 3 m below the sensor spreads over 1.76e-3 z^2. Seen from a
// sensor h above the floor, a floor point at depth z moves by this times z h upwards.
constexpr double kDepthNoiseWithStepsPerM2 = 1.65e-3;

// That noise's part along the floor's normal (m, one standard deviation) for a point near the
// floor at depth `depth_m`, seen from a sensor `sensor_height_m` above it.
inline float DepthNoiseInHeight(float depth_m, float sensor_height_m) {
  return static_cast<float>(kDepthNoiseWithStepsPerM2) * depth_m * sensor_height_m;
}

// Inlier half-width (m) of a point at squared range `range2` (m^2) for a base threshold (m).
inline float FloorInlierBand(float threshold_m, float range2) {
  return threshold_m + static_cast<float>(2.5 * kFloorDepthNoisePerM2) * range2;
}

// Weighted least-squares plane (weighted centroid + smallest principal axis) through
// points[indices] with weights 1 / sigma^2, sigma^2 = (threshold / 2)^2 + (k r^2)^2; oriented so
// that the sensor (origin) is on its positive side. Returns false when degenerate (fewer than 3
// points, collinear).
bool FitFloorPlaneLeastSquares(const std::vector<Eigen::Vector3f>& points,
                               const std::vector<int>& indices, double threshold_m,
                               Eigen::Vector4d* plane);

// Indices of the points within the range-dependent inlier band of the plane.
void SelectFloorInliers(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector4d& plane,
                        double threshold_m, std::vector<int>* inliers);

// Points farther below the plane (on the side away from the sensor) than twice their inlier band
// plus 3 cm: nothing should lie there if the plane is the floor.
size_t CountBelowFloorPlane(const std::vector<Eigen::Vector3f>& points,
                            const Eigen::Vector4d& plane, double threshold_m);

// How wide the points[indices] spread over the plane across their longest direction (metres):
// the 5th to 95th percentile of their in-plane offsets along the minor principal axis. A floor
// seen from a sensor's minimum range on is a broad patch; a plane that cuts a strip through the
// sides of objects (when no floor is in view) is narrow. 0 for fewer than 3 points.
double FloorInlierWidth(const std::vector<Eigen::Vector3f>& points, const std::vector<int>& indices,
                        const Eigen::Vector4d& plane);

}  // namespace hpose

#endif  // HPOSE_CORE_DEPTH_FLOOR_PLANE_H_
