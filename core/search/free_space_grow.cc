#include "core/search/free_space_grow.h"

#include <algorithm>
#include <cmath>

#include "core/scoring/pose_lattice.h"

namespace hpose {

std::vector<int> FreeSpaceGrow(const VoxelTemplate& tpl, double origin_margin_m,
                               double resolution_m) {
  std::vector<double> reach;
  for (const Eigen::Vector3f& v : tpl.voxels) {
    const int z = CellOf(v, resolution_m).z();
    if (z < 0) continue;
    if (z >= static_cast<int>(reach.size())) reach.resize(z + 1, -1.0);
    reach[z] = std::max(reach[z], static_cast<double>(v.head<2>().norm()));
  }
  std::vector<int> grow;
  grow.reserve(reach.size());
  for (const double r : reach) {
    grow.push_back(r < 0.0 ? -1
                           : static_cast<int>(std::ceil((origin_margin_m + r + 2.0 * resolution_m) /
                                                        resolution_m)));
  }
  return grow;
}

}  // namespace hpose
