#ifndef HPOSE_CORE_DEPTH_FLOOR_FITTER_H_
#define HPOSE_CORE_DEPTH_FLOOR_FITTER_H_

#include "core/common/status.h"
#include "core/depth/floor_estimate.h"
#include "core/depth/point_cloud.h"

namespace hpose {

struct FloorFitterOptions {
  double distance_threshold_m = 0.015;  // RANSAC inlier band.
  int max_iterations = 200;
  // The floor normal must be within this angle of the sensor's "up" guess (-y in the sensor
  // frame): rejects walls. 60 degrees allows any reasonable pitch and roll.
  double max_tilt_rad = 1.0472;
  double min_inlier_fraction = 0.05;  // of the (downsampled) points.
  double downsample_leaf_m = 0.02;    // voxel grid before RANSAC; 0 disables.
  int random_seed = 0;                // fixed seed: the same frame gives the same floor.
};

// RANSAC plane fit (PCL) for the floor, among planes nearly perpendicular to the sensor's up
// guess, preferring the lowest such plane (largest d). Fails with kFailedPrecondition naming why
// ("no floor: only 37 points", "no floor: best plane has 2% inliers") or kInvalidArgument for an
// empty cloud.
Result<FloorEstimate> FitFloor(const PointCloud& cloud_sensor,
                               const FloorFitterOptions& options = {});

}  // namespace hpose

#endif  // HPOSE_CORE_DEPTH_FLOOR_FITTER_H_
