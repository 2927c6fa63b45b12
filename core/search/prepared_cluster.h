#ifndef HPOSE_CORE_SEARCH_PREPARED_CLUSTER_H_
#define HPOSE_CORE_SEARCH_PREPARED_CLUSTER_H_

#include <vector>

#include <Eigen/Geometry>

#include "core/search/pose_refiner.h"
#include "core/search/refine_terms.h"

namespace hpose {

// The cluster's side of the refinement's objective, which no pose and no template changes:
// every stride-th cluster point (RefineOptions::max_data_points) with its sensor-frame position,
// ray, noise, association gate and unexplained cost, and for those in front of the sensor their
// ray slopes. Made once per cluster and read by every refinement and evaluation of its templates
// (Observation::prepared), or once per refinement when not given. Immutable, shareable between
// threads.
class PreparedCluster {
 public:
  PreparedCluster(const std::vector<Eigen::Vector3f>& points,
                  const Eigen::Isometry3d& sensor_from_ground, const RefineOptions& options);

  // Whether it was made from these points (the same vector), this mount and options that give
  // the same data (the points' count and the noise model).
  bool Matches(const std::vector<Eigen::Vector3f>& points,
               const Eigen::Isometry3d& sensor_from_ground, const RefineOptions& options) const;

  size_t size() const { return data_.size(); }
  const refine_terms::DataPoint& point(size_t k) const { return data_[k]; }
  bool in_front(size_t k) const { return in_front_[k] != 0; }
  // Ray slopes x / z and y / z (sensor frame) of a point in front of the sensor (else 0).
  double tx(size_t k) const { return tx_[k]; }
  double ty(size_t k) const { return ty_[k]; }

 private:
  const std::vector<Eigen::Vector3f>* points_;
  Eigen::Isometry3d sensor_from_ground_;
  RefineOptions options_;
  std::vector<refine_terms::DataPoint> data_;
  std::vector<double> tx_, ty_;
  std::vector<unsigned char> in_front_;
};

}  // namespace hpose

#endif  // HPOSE_CORE_SEARCH_PREPARED_CLUSTER_H_
