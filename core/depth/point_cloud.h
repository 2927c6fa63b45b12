#ifndef HPOSE_CORE_DEPTH_POINT_CLOUD_H_
#define HPOSE_CORE_DEPTH_POINT_CLOUD_H_

#include <vector>

#include <Eigen/Core>

namespace hpose {

// A point cloud in metres. In the sensor frame (x right, y down, z forward) unless a function
// says otherwise. Organised when width * height == points.size() (invalid pixels are NaN).
struct PointCloud {
  std::vector<Eigen::Vector3f> points;
  int width = 0;   // 0 when unorganised.
  int height = 0;  // 0 when unorganised.

  bool organised() const {
    return width > 0 && height > 0 && static_cast<size_t>(width) * height == points.size();
  }
  size_t size() const { return points.size(); }
  bool empty() const { return points.empty(); }
};

}  // namespace hpose

#endif  // HPOSE_CORE_DEPTH_POINT_CLOUD_H_
