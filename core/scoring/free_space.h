#ifndef HPOSE_CORE_SCORING_FREE_SPACE_H_
#define HPOSE_CORE_SCORING_FREE_SPACE_H_

#include <Eigen/Geometry>

#include "core/depth/range_image.h"
#include "core/scoring/pose_scorer.h"

namespace hpose {

struct FreeSpaceOptions {
  // A voxel is free when the sensor saw farther than its centre by at least
  // margin_m + sigma_factor * sigma(z), sigma(z) = 1.425e-3 z^2 (Kinect v1 axial noise, SPEC §5).
  double margin_m = 0.024;  // 1.5 voxels: the voxel's own extent.
  double sigma_factor = 3.0;
};

// The voxel cells (CellOf at `resolution_m`, ground frame) within [lo, hi] (inclusive) that the
// sensor saw through: the ray to the voxel's centre met a surface clearly beyond it. Voxels
// that are hidden behind something, out of view, or without a reading are not free (unknown).
ClusterVoxels FreeSpaceCells(const RangeImage& range, const Eigen::Isometry3d& sensor_from_ground,
                             const Eigen::Vector3i& lo, const Eigen::Vector3i& hi,
                             double resolution_m, const FreeSpaceOptions& options = {});
// The same cells, one matrix product per cell (the straightforward form the above is tested
// against).
ClusterVoxels FreeSpaceCellsReference(const RangeImage& range,
                                      const Eigen::Isometry3d& sensor_from_ground,
                                      const Eigen::Vector3i& lo, const Eigen::Vector3i& hi,
                                      double resolution_m, const FreeSpaceOptions& options = {});

}  // namespace hpose

#endif  // HPOSE_CORE_SCORING_FREE_SPACE_H_
