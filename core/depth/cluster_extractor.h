#ifndef HPOSE_CORE_DEPTH_CLUSTER_EXTRACTOR_H_
#define HPOSE_CORE_DEPTH_CLUSTER_EXTRACTOR_H_

#include <vector>

#include "core/common/status.h"
#include "core/depth/cluster.h"
#include "core/depth/floor_estimate.h"
#include "core/depth/ground_band.h"
#include "core/depth/point_cloud.h"

namespace hpose {

// Defaults suit both use cases of hpose: a 58 cm humanoid seen from 0.3-1 m height and 1-4 m
// away, and people seen from a tripod (tuned on a real 640x480 Kinect frame of five people).
struct ClusterOptions {
  // Points lower than this are floor. 4 cm rather than 2: Kinect depth noise and floor-fit
  // error reach 2-3 cm at 3-4 m, and floor speckle would otherwise glue feet to the floor.
  double min_height_above_floor_m = 0.04;
  // ... or lower than this many standard deviations of the vertical part of their depth noise:
  // seen from high up and steeply (a sensor near the ceiling), a floor 3 m away is noisy along
  // the rays and so in height (a Kinect v1's sigma_z = 1.65e-3 z^2 along a ray with its
  // disparity steps, (sensor height) / z of it upwards: 1.4 cm for a sensor 2.9 m high at 80
  // degrees), and its speckle above 4 cm joins everything standing on it into one cluster too
  // wide to keep. Mounts up to 1 m high never reach 4 cm this way. 0 disables.
  double floor_noise_sigmas = 4.0;
  double max_height_above_floor_m = 2.5;  // points higher are ignored (ceiling, walls).
  double max_range_m = 5.0;               // horizontal distance from the sensor.
  // Voxel grid of the output points; half the 16 mm scoring voxel so every occupied scoring
  // voxel keeps a point. 0 disables.
  double downsample_leaf_m = 0.008;
  double tolerance_m = 0.04;  // Euclidean cluster tolerance.
  // How the Euclidean clusters are found; both give the same clusters (same points, same
  // order). kGrid: connected components over a bucket grid of the tolerance (fast). kPcl: PCL's
  // kd-tree radius searches (the reference).
  enum class Method { kGrid, kPcl };
  Method method = Method::kGrid;
  // After downsampling. 200 drops slivers of far walls (sparse, yet person-tall) while a 58 cm
  // humanoid 4 m from a 320x240 sensor still gives ~900 points.
  int min_points = 200;
  int max_points = 200000;
  double min_height_m = 0.10;  // cluster top above the floor, filters flat debris.
  double max_height_m = 2.5;
  double max_footprint_m = 1.5;  // the larger horizontal bbox side.
  // Organised clouds only: drop points whose segment to the pixel two steps away lies within
  // this angle (rad) of the viewing ray, i.e. mixed pixels interpolated across depth jumps that
  // glue an object to what stands behind it (on the five-people Kinect frame, 17 degrees
  // separates two people 30 cm apart in depth that 8 degrees does not). Surfaces seen at more
  // than ~73 degrees incidence go too. 0 disables.
  double veil_max_angle_rad = 0.3;
  // Objects in contact form one Euclidean cluster; such a cluster is split around its tops
  // (highest points) that are at least this far apart horizontally, when every part keeps a
  // fifth of the points (so an arm or a hand is never split off). 0 disables, the default: a
  // humanoid seen from the side has its head and its arm as two such tops and was split in two
  // (the veil filter alone already separates the touching people of the five-people frame).
  double split_min_top_separation_m = 0.0;
  // Pieces of one object split by a depth edge inside it are merged (MergePiecesAlongSight):
  // clusters overlapping in bearing by this fraction of the narrower one (0 disables) ...
  double merge_min_bearing_overlap = 0.5;
  // ... whose horizontal range intervals are less than this apart.
  double merge_max_range_gap_m = 0.08;
  // A limb whose joint the body hides (an arm raised on the far side of a robot seen side-on)
  // is a piece behind the body's silhouette in the image: merged when it has at most
  // merge_hidden_max_fraction of the body's points and lies less than
  // merge_hidden_max_depth_gap_m behind it at their common edge (MergeOccludedPieces; 0
  // disables). 0.3 m: the width of a 1.5 m person's shoulders, more than a small robot's.
  double merge_hidden_max_depth_gap_m = 0.30;
  double merge_hidden_max_fraction = 0.5;
  // ... unless it stands where the body stands: its lowest point less than this above the body's
  // and its top below the body's mid-height, an object behind it (OccludedPieceOptions::
  // min_lift_m; 0: any piece).
  double merge_hidden_min_lift_m = 0.05;
};

// kInvalidArgument naming the first option out of range ("cluster options: tolerance_m must be >
// 0"); ExtractClusters checks this first, Estimator::Create at start.
Status ValidateClusterOptions(const ClusterOptions& options);

// Transforms the cloud to the ground frame, keeps points above the floor, downsamples and
// splits them into Euclidean clusters (PCL), filtered by size and height. Clusters are sorted by
// point count, largest first. An empty result is not an error. Fails (kInvalidArgument) only on
// invalid options or a degenerate floor (ValidateFloor).
// Details: organised clouds lose their mixed pixels at depth jumps (veil_max_angle_rad);
// clusters with several tops are split (split_min_top_separation_m); clusters reaching within
// max(2 tolerance_m, 0.1 m) of max_range_m or max_height_above_floor_m are dropped as cut-off
// pieces (walls, furniture at the edge of the working volume). Cluster points are the voxel-grid
// centroids.
Result<std::vector<Cluster>> ExtractClusters(const PointCloud& cloud_sensor,
                                             const FloorEstimate& floor,
                                             const ClusterOptions& options = {});

// The slab of space ExtractClusters looks in (its first step): the floor's ground frame, the
// options' heights above the floor and horizontal range.
GroundBand ClusterGroundBand(const FloorEstimate& floor, const ClusterOptions& options);

}  // namespace hpose

#endif  // HPOSE_CORE_DEPTH_CLUSTER_EXTRACTOR_H_
