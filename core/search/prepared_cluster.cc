#include "core/search/prepared_cluster.h"

namespace hpose {

PreparedCluster::PreparedCluster(const std::vector<Eigen::Vector3f>& points,
                                 const Eigen::Isometry3d& sensor_from_ground,
                                 const RefineOptions& options)
    : points_(&points), sensor_from_ground_(sensor_from_ground), options_(options) {
  const size_t stride = refine_terms::DataStride(points.size(), options);
  data_.reserve(points.size() / stride + 1);
  for (size_t k = 0; k < points.size(); k += stride) {
    const refine_terms::DataPoint d =
        refine_terms::MakeDataPoint(points[k], sensor_from_ground, options);
    const bool front = d.ps.z() > refine_terms::kMinViewDepth;
    data_.push_back(d);
    in_front_.push_back(front ? 1 : 0);
    tx_.push_back(front ? d.ps.x() / d.ps.z() : 0.0);
    ty_.push_back(front ? d.ps.y() / d.ps.z() : 0.0);
  }
}

bool PreparedCluster::Matches(const std::vector<Eigen::Vector3f>& points,
                              const Eigen::Isometry3d& sensor_from_ground,
                              const RefineOptions& o) const {
  const RefineOptions& p = options_;
  return &points == points_ && sensor_from_ground.matrix() == sensor_from_ground_.matrix() &&
         o.max_data_points == p.max_data_points && o.axial_coeff == p.axial_coeff &&
         o.step_coeff == p.step_coeff && o.lateral_rad == p.lateral_rad &&
         o.model_sigma_m == p.model_sigma_m && o.cauchy_scale == p.cauchy_scale &&
         o.association_gate_m == p.association_gate_m;
}

}  // namespace hpose
