#ifndef HPOSE_CORE_DEPTH_LOCAL_PLANE_RANSAC_H_
#define HPOSE_CORE_DEPTH_LOCAL_PLANE_RANSAC_H_

#include <vector>

#include <Eigen/Core>

namespace hpose {

struct LocalPlaneRansacOptions {
  double distance_threshold_m = 0.015;  // inlier band, each side of the plane.
  // The 2nd and 3rd points of a hypothesis lie within this radius of the 1st: a hypothesis is
  // all-plane with probability ~w (the plane's fraction of the points) instead of w^3.
  double sample_radius_m = 0.4;
  // Planes whose normal is more than max_axis_angle_rad from +-axis are not counted.
  Eigen::Vector3f axis = Eigen::Vector3f(0.0f, -1.0f, 0.0f);
  double max_axis_angle_rad = 1.2217;
  int max_iterations = 200;
  // Stop once a better plane would have been drawn with this probability (from the best inlier
  // fraction so far, as for three independent draws).
  double probability = 0.99;
  unsigned seed = 0;  // the same points and seed give the same plane.
};

struct LocalPlaneRansacResult {
  bool found = false;
  Eigen::Vector4f plane = Eigen::Vector4f::Zero();  // unit normal n and d: n.p + d = 0.
  int inliers = 0;     // points within distance_threshold_m of the plane.
  int hypotheses = 0;  // planes counted.
};

// RANSAC for the plane with the most points within the band, among planes nearly perpendicular
// to an axis, from hypotheses of three points drawn close together (NeighbourSampler). Found
// when some hypothesis has at least three inliers. Points must be finite.
LocalPlaneRansacResult FitPlaneLocalRansac(const std::vector<Eigen::Vector3f>& points,
                                           const LocalPlaneRansacOptions& options);

}  // namespace hpose

#endif  // HPOSE_CORE_DEPTH_LOCAL_PLANE_RANSAC_H_
