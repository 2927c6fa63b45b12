#include "core/scoring/free_space.h"

namespace hpose {

ClusterVoxels FreeSpaceCells(const RangeImage& range, const Eigen::Isometry3d& sensor_from_ground,
                             const Eigen::Vector3i& lo, const Eigen::Vector3i& hi,
                             double resolution_m, const FreeSpaceOptions& options) {
  ClusterVoxels free;
  free.resolution_m = resolution_m;
  const Eigen::Matrix3d r = sensor_from_ground.linear();
  const Eigen::Vector3d t = sensor_from_ground.translation();
  for (int x = lo.x(); x <= hi.x(); ++x) {
    for (int y = lo.y(); y <= hi.y(); ++y) {
      // Walk the column; cells are sorted (x, y, z) as VoxeliseCluster sorts them.
      for (int z = lo.z(); z <= hi.z(); ++z) {
        const Eigen::Vector3d centre((x + 0.5) * resolution_m, (y + 0.5) * resolution_m,
                                     (z + 0.5) * resolution_m);
        const Eigen::Vector3d s = r * centre + t;
        const double seen = range.DepthToward(s);
        if (seen <= 0.0) continue;
        const double sigma = 1.425e-3 * seen * seen;
        if (seen > s.z() + options.margin_m + options.sigma_factor * sigma) {
          free.cells.emplace_back(x, y, z);
        }
      }
    }
  }
  return free;
}

}  // namespace hpose
