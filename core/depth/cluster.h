#ifndef HPOSE_CORE_DEPTH_CLUSTER_H_
#define HPOSE_CORE_DEPTH_CLUSTER_H_

#include <vector>

#include <Eigen/Core>

namespace hpose {

// One object standing on the floor, in the ground frame (metres).
struct Cluster {
  std::vector<Eigen::Vector3f> points;
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
  Eigen::Vector3f min = Eigen::Vector3f::Zero();
  Eigen::Vector3f max = Eigen::Vector3f::Zero();

  float height() const { return max.z(); }
};

}  // namespace hpose

#endif  // HPOSE_CORE_DEPTH_CLUSTER_H_
