#ifndef HPOSE_CORE_SCORING_FREE_SPACE_H_
#define HPOSE_CORE_SCORING_FREE_SPACE_H_

#include <vector>

#include <Eigen/Geometry>

#include "core/depth/range_image.h"
#include "core/scoring/pose_scorer.h"

namespace hpose {

struct FreeSpaceOptions {
  // A voxel is free when the sensor saw farther than its centre by at least
  // margin_m + sigma_factor * sigma(z), sigma(z) = 1.425e-3 z^2 (Kinect v1 axial noise, SPEC §5).
  double margin_m = 0.024;  // 1.5 voxels: the voxel's own extent.
  double sigma_factor = 3.0;
  // Seen from steeply above (a sensor high up looking down), a body's sides are grazed by the
  // rays along their whole height, and a voxel a few millimetres beside one (the template's
  // voxels against the true surface, the lattice's steps) is seen through to the floor: where a
  // ray points at least this far below the horizon, a voxel is free only when the nearest depth
  // among the 3 x 3 range-image bins around its ray lies beyond it (the estimator's range image,
  // RangeImage::NearestAroundSteepRays: about +-8 mm at 2.5 m). 70 degrees: no mount of up to 45
  // degrees down sees such rays (a Kinect v1's vertical half field of view is about 22 degrees);
  // above 90: off.
  double steep_ray_rad = 70.0 * 3.14159265358979323846 / 180.0;
};

// Where free space is wanted: the box of columns [core_lo, core_hi] (x, y cells, inclusive),
// grown per z layer by as many cells as is read there (the cells a template placed by the
// searches can reach, which depend on the template's width at that height).
struct FreeSpaceRegion {
  Eigen::Vector2i core_lo{0, 0}, core_hi{-1, -1};
  int z_lo = 0;           // the layer of grow[0].
  std::vector<int> grow;  // per layer z_lo + k: cells added on every side; < 0: no cells.
};

// The region around a cluster's voxels (non-empty): their columns' box, grown per layer by
// `grow` from layer 0 (the floor).
FreeSpaceRegion FreeSpaceRegionAround(const ClusterVoxels& voxels, std::vector<int> grow);

// The voxel cells of `region` (CellOf at `resolution_m`, ground frame) that the sensor saw
// through: the ray to the voxel's centre met a surface clearly beyond it. Voxels that are hidden
// behind something, out of view, or without a reading are not free (unknown). Sorted (x, y, z).
ClusterVoxels FreeSpaceCells(const RangeImage& range, const Eigen::Isometry3d& sensor_from_ground,
                             const FreeSpaceRegion& region, double resolution_m,
                             const FreeSpaceOptions& options = {});
// FreeSpaceCells takes eight heights of a column a step: with AVX-512 where the CPU has it
// (FreeSpaceEightLanes()), else with AVX2 (FreeSpaceCellsAvx2, where FreeSpaceAvx2Available()).
// Without either it takes four (FreeSpaceCellsFourLanes). Both of the latter are callable for
// tests whatever else the CPU has (FreeSpaceCellsAvx2 takes four heights without AVX2).
ClusterVoxels FreeSpaceCellsFourLanes(const RangeImage& range,
                                      const Eigen::Isometry3d& sensor_from_ground,
                                      const FreeSpaceRegion& region, double resolution_m,
                                      const FreeSpaceOptions& options = {});
ClusterVoxels FreeSpaceCellsAvx2(const RangeImage& range,
                                 const Eigen::Isometry3d& sensor_from_ground,
                                 const FreeSpaceRegion& region, double resolution_m,
                                 const FreeSpaceOptions& options = {});
bool FreeSpaceEightLanes();
bool FreeSpaceAvx2Available();
// The same cells, one matrix product per cell (the straightforward form the above are tested
// against).
ClusterVoxels FreeSpaceCellsReference(const RangeImage& range,
                                      const Eigen::Isometry3d& sensor_from_ground,
                                      const FreeSpaceRegion& region, double resolution_m,
                                      const FreeSpaceOptions& options = {});

// The same for the box [lo, hi] (cells, inclusive): every layer of lo.z() .. hi.z() over the
// columns [lo, hi].
ClusterVoxels FreeSpaceCells(const RangeImage& range, const Eigen::Isometry3d& sensor_from_ground,
                             const Eigen::Vector3i& lo, const Eigen::Vector3i& hi,
                             double resolution_m, const FreeSpaceOptions& options = {});
ClusterVoxels FreeSpaceCellsReference(const RangeImage& range,
                                      const Eigen::Isometry3d& sensor_from_ground,
                                      const Eigen::Vector3i& lo, const Eigen::Vector3i& hi,
                                      double resolution_m, const FreeSpaceOptions& options = {});

}  // namespace hpose

#endif  // HPOSE_CORE_SCORING_FREE_SPACE_H_
