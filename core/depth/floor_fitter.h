#ifndef HPOSE_CORE_DEPTH_FLOOR_FITTER_H_
#define HPOSE_CORE_DEPTH_FLOOR_FITTER_H_

#include "core/common/status.h"
#include "core/depth/floor_estimate.h"
#include "core/depth/point_cloud.h"

namespace hpose {

struct FloorFitterOptions {
  // RANSAC inlier band. The least-squares refinement widens it with range by the Kinect v1
  // noise model (SPEC §5) and weights far points down.
  double distance_threshold_m = 0.015;
  // Per candidate plane. Hypotheses are drawn from 0.4 m neighbourhoods, so a floor that is a
  // small minority of the points is still hit within a few dozen draws.
  int max_iterations = 200;
  // The floor normal must be within this angle of the sensor's "up" guess (-y in the sensor
  // frame): rejects walls. 70 degrees allows a 60 degree pitch combined with some roll; a
  // sensor looking down more steeply (mounted high, near the ceiling) needs more, up to just
  // short of 90 (the ground frame's x axis, the optical axis projected on the floor, is then
  // taken from an ever shorter projection: at 85 degrees a floor normal off by 0.1 degree
  // across turns it by about 1 degree).
  double max_tilt_rad = 70.0 * 3.14159265358979323846 / 180.0;
  double min_inlier_fraction = 0.05;  // of the (downsampled) points.
  // A floor's inliers spread at least this wide across their longest direction (FloorInlierWidth,
  // metres). Seen from a Kinect's minimum range of 0.8 m on, the floor is a patch over half a metre
  // wide even at a steep pitch; with no floor in view (a sensor pitched up), the planes left are
  // strips cut through the sides of objects, 0.1-0.3 m wide. 0 disables the check.
  double min_width_m = 0.35;
  // Voxel grid before RANSAC; 0 disables. 3 cm: voxel centroids of a plane stay on it, and
  // fewer points make the fit cheap (clouds above 20k points are thinned on a pixel lattice
  // first).
  double downsample_leaf_m = 0.03;
  // Points of a candidate floor with points 9 or 15 cm above them (in the 6 cm cells there,
  // along the plane's normal; higher where the floor's depth noise reaches higher) are the feet
  // of what stands on the floor: a box's sides, a ball's underside, a robot's soles. They lie
  // within the inlier band and are left out of the least-squares fits, which they otherwise
  // lean towards them where little floor is in view (a sensor low down or pitched up sees the
  // floor only near its feet: a ball 2.3 m away tilted the floor of a sensor 0.3 m up, pitched
  // 10 degrees up, by 2.5 degrees). They still count as inliers.
  bool skip_object_feet = true;
  int random_seed = 0;  // fixed seed: the same frame gives the same floor.
};

// kInvalidArgument naming the first option out of range ("floor fitter options: min_width_m must
// be finite and >= 0"); FitFloor checks this first, Estimator::Create at start.
Status ValidateFloorFitterOptions(const FloorFitterOptions& options);

// RANSAC plane fit (FitPlaneLocalRansac) for the floor, among planes nearly perpendicular to the
// sensor's up guess, preferring the lowest such plane (largest d). Fails with kFailedPrecondition
// naming why ("no floor: only 37 points", "no floor: best plane has 2% inliers") or
// kInvalidArgument for an empty cloud or invalid options.
// Up to six near-horizontal planes are extracted in turn. One with many points beneath it, a
// parallel plane clearly below it (table, box top, a slanted cut through walls), inliers in a
// narrow strip (min_width_m), passing within 5 cm of the sensor or meaning a sensor rolled more
// than 45 degrees about its optical axis (a wall beside it) is not the floor; among the
// rest the best supported wins (so a wall seen from a steep pitch does not beat the floor). The
// winner is refined by weighted least squares, last on the thinned points rather than the voxel
// centroids (the near floor, more precise, then weighs more), keeping the candidates' tilt and
// height limits. FloorEstimate::inliers counts downsampled points. NaN points are ignored.
Result<FloorEstimate> FitFloor(const PointCloud& cloud_sensor,
                               const FloorFitterOptions& options = {});

}  // namespace hpose

#endif  // HPOSE_CORE_DEPTH_FLOOR_FITTER_H_
