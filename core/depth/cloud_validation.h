#ifndef HPOSE_CORE_DEPTH_CLOUD_VALIDATION_H_
#define HPOSE_CORE_DEPTH_CLOUD_VALIDATION_H_

#include <cstddef>

#include "core/common/status.h"
#include "core/depth/floor_estimate.h"
#include "core/depth/point_cloud.h"

namespace hpose {

// What a cloud handed to the estimator may hold. Everything downstream (voxel grids summing
// coordinates, the floor's rigid transform, PCL's kd-trees, which abort on a non-finite point)
// stays finite for clouds within these limits.
struct CloudLimits {
  // Largest coordinate magnitude (metres, any axis) of a point: a range camera sees metres to
  // tens of metres; 1 km leaves room for any sensor and is far from float overflow.
  double max_abs_coordinate_m = 1000.0;
  // Most points in one cloud (an 8192 x 8192 organised cloud, the largest Intrinsics allow).
  std::size_t max_points = std::size_t{8192} * 8192;
};

// Checks a cloud (sensor frame, metres) before any processing. A point with a NaN coordinate is
// a missing reading and is allowed (it is skipped later); every other point must have finite
// coordinates within +-max_abs_coordinate_m. Fails with kInvalidArgument naming the first
// offending point (its index and coordinates) and how many points offend, or the point count
// when it exceeds max_points.
// With `finite_points`, also counts the points that are not missing (on success: every point
// that is not NaN), in the same pass.
//
// Counted sixteen points a step with AVX-512, eight with AVX2, else one at a time:
// ValidateCloudScalar is that reference, ValidateCloudAvx2 the AVX2 pass whatever else the CPU
// has (only where CloudValidationAvx2Available()), for tests. All give the same result.
Status ValidateCloud(const PointCloud& cloud, const CloudLimits& limits = {},
                     std::size_t* finite_points = nullptr);
Status ValidateCloudScalar(const PointCloud& cloud, const CloudLimits& limits = {},
                           std::size_t* finite_points = nullptr);
Status ValidateCloudAvx2(const PointCloud& cloud, const CloudLimits& limits = {},
                         std::size_t* finite_points = nullptr);
bool CloudValidationAvx2Available();

// Checks a floor (fitted or fixed) before points are moved into its ground frame: the plane and
// ground_from_sensor must be finite, the rotation orthonormal (a floor seen edge-on or along the
// optical axis has no ground frame) and the sensor height within [0, max_abs_coordinate_m].
// Fails with kInvalidArgument naming what is wrong.
Status ValidateFloor(const FloorEstimate& floor, const CloudLimits& limits = {});

}  // namespace hpose

#endif  // HPOSE_CORE_DEPTH_CLOUD_VALIDATION_H_
