#ifndef HPOSE_CORE_TEMPLATES_CAPTURE_VIEWS_H_
#define HPOSE_CORE_TEMPLATES_CAPTURE_VIEWS_H_

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/common/status.h"
#include "core/depth/cluster_extractor.h"
#include "core/depth/floor_estimate.h"
#include "core/depth/floor_fitter.h"
#include "core/depth/point_cloud.h"

namespace hpose {

// One capture of the robot: a cloud in the sensor frame (x right, y down, z forward, metres),
// preferably organised (a depth image back-projected), and the name errors use (its file).
struct CaptureView {
  std::string name;
  PointCloud cloud_sensor;
};

struct CaptureViewOptions {
  FloorFitterOptions floor;
  // Each fitted floor is refined over the points within this distance of it (more at long
  // range, by the noise model), metres: a table top above it does not tilt it.
  double floor_band_m = 0.008;
  // Clustering of what stands on the floor; min_height_above_floor_m is replaced by
  // table_height_m + cut_above_table_m.
  ClusterOptions clusters;
  // Height of the surface the robot stands on (a turntable's top) above the floor, metres;
  // 0 when it stands on the floor. The robot's points are returned relative to it (z = 0 on it).
  double table_height_m = 0.0;
  // Points lower than this above the table top are dropped with the table (its noise and the
  // disc's rim), metres.
  double cut_above_table_m = 0.025;
  // The robot's cluster must be at least this tall above the table top, metres.
  double min_robot_height_m = 0.15;
  // All captures come from one fixed sensor: every view's floor must agree with the median
  // floor within these (else the view is refused as coming from another set-up).
  double max_floor_height_difference_m = 0.02;
  double max_floor_angle_difference_rad = 0.035;  // 2 degrees.
  // A view whose chosen cluster stands farther than this from the other views' median
  // position is re-assigned to the cluster nearest that median, metres.
  double max_robot_shift_m = 0.5;
  // false: a view that fails (no floor, no robot, another floor) fails the whole call, naming
  // it. true: it is left out and listed in CaptureViews::dropped.
  bool drop_bad_views = false;
};

// The robot cut out of one capture, in the ground frame of the common floor (origin on the
// floor below the sensor, x the optical axis on the floor, z up) with z measured from the table
// top.
struct RobotView {
  std::string name;
  int capture_index = 0;                // position in the captures given.
  std::vector<Eigen::Vector3f> points;  // ground frame, z above the table top, metres.
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
  FloorEstimate own_floor;                 // this view's fitted floor.
  double floor_height_difference_m = 0.0;  // own floor vs the common one.
  double floor_angle_difference_rad = 0.0;
  int clusters_seen = 0;  // clusters standing on the floor in this view.
};

// A view left out, and why ("no floor: ...", "floor 45 mm higher than the other views'").
struct DroppedView {
  std::string name;
  std::string reason;
};

struct CaptureViews {
  FloorEstimate floor;  // the common floor of the kept views (mean of their planes).
  std::vector<RobotView> views;
  std::vector<DroppedView> dropped;
};

using ProgressFn = std::function<void(const std::string& line)>;

// Fits the floor of every view (FitFloor), checks that all views see the same floor (one fixed
// sensor), clusters what stands on it and cuts the robot out: in every view the cluster at
// least min_robot_height_m tall whose centroid bearing is nearest the optical axis (ties: more
// points), then views whose pick stands far from the others' median position take the cluster
// nearest to it (clutter elsewhere in the room does not matter). Fails naming the view: no
// views (kInvalidArgument), no floor or no robot-sized cluster in a view, or a floor that
// disagrees (kFailedPrecondition) -- unless options.drop_bad_views, which leaves such views out
// (at least two must remain). `progress` (may be empty) receives one line per view.
Result<CaptureViews> ExtractRobotViews(const std::vector<CaptureView>& captures,
                                       const CaptureViewOptions& options,
                                       const ProgressFn& progress = {});

}  // namespace hpose

#endif  // HPOSE_CORE_TEMPLATES_CAPTURE_VIEWS_H_
