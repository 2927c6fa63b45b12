#ifndef HPOSE_CORE_DEPTH_CLUSTER_EXTRACTOR_H_
#define HPOSE_CORE_DEPTH_CLUSTER_EXTRACTOR_H_

#include <vector>

#include "core/common/status.h"
#include "core/depth/cluster.h"
#include "core/depth/floor_estimate.h"
#include "core/depth/point_cloud.h"

namespace hpose {

struct ClusterOptions {
  double min_height_above_floor_m = 0.02;  // points lower than this are floor.
  double max_height_above_floor_m = 2.5;   // points higher are ignored (ceiling, walls).
  double max_range_m = 5.0;                // horizontal distance from the sensor.
  double downsample_leaf_m = 0.008;        // voxel grid before clustering; 0 disables.
  double tolerance_m = 0.04;               // Euclidean cluster tolerance.
  int min_points = 30;                     // after downsampling.
  int max_points = 200000;
  double min_height_m = 0.10;  // cluster top above the floor, filters flat debris.
  double max_height_m = 2.5;
  double max_footprint_m = 1.5;  // the larger horizontal bbox side.
};

// Transforms the cloud to the ground frame, keeps points above the floor, downsamples and
// splits them into Euclidean clusters (PCL), filtered by size and height. Clusters are sorted by
// point count, largest first. An empty result is not an error. Fails (kInvalidArgument) only on
// invalid options.
Result<std::vector<Cluster>> ExtractClusters(const PointCloud& cloud_sensor,
                                             const FloorEstimate& floor,
                                             const ClusterOptions& options = {});

}  // namespace hpose

#endif  // HPOSE_CORE_DEPTH_CLUSTER_EXTRACTOR_H_
