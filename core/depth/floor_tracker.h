#ifndef HPOSE_CORE_DEPTH_FLOOR_TRACKER_H_
#define HPOSE_CORE_DEPTH_FLOOR_TRACKER_H_

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/common/status.h"
#include "core/depth/floor_estimate.h"
#include "core/depth/floor_fitter.h"
#include "core/depth/point_cloud.h"

namespace hpose {

struct FloorTrackerOptions {
  FloorFitterOptions fit;  // the full fit (FitFloor): first frame and whenever the floor changed.
  // The check on a new frame looks at about this many points of the cloud (a pixel lattice of
  // an organised cloud, every k-th point otherwise).
  int check_points = 4000;
  // The kept floor still fits while, on the checked points: the fraction within its inlier
  // band stays at least this share of the fraction right after the last fit (something large
  // in front of the sensor, or a moved sensor, lowers it) ...
  double min_inlier_ratio = 0.6;
  // ... at most this fraction of them lies well below it (the sensor was lowered or tilted) ...
  double max_below_fraction = 0.005;
  // ... and the plane fitted by least squares to those inliers has not moved from the one
  // measured the same way right after the last fit by more than these (small drifts of the
  // mount that stay within the inlier band).
  double max_tilt_change_rad = 0.0175;  // 1 degree.
  double max_height_change_m = 0.01;
  // Refit after this many frames of reuse even when the floor still fits; 0 never forces one.
  int max_reuse_frames = 0;
};

// Tracks the floor over a stream of frames from one sensor: the first frame gets a full fit
// (FitFloor); each later frame is checked cheaply against the kept floor (a few thousand
// points, see FloorTrackerOptions) and the kept floor is returned unchanged while it still
// fits, so a fixed sensor pays for one fit instead of one per frame and poses are computed in
// one ground frame. When the check fails the frame is fitted again. Not thread-safe: one
// tracker per stream.
class FloorTracker {
 public:
  explicit FloorTracker(FloorTrackerOptions options = {});

  // The floor of this frame (sensor-frame cloud, organised or not; NaN points ignored): the
  // kept floor when it still fits, else a fresh fit. Fails like FitFloor (kInvalidArgument for an
  // empty cloud or invalid options, kFailedPrecondition when no floor is found); after a failure
  // the next frame is fitted from scratch.
  Result<FloorEstimate> Update(const PointCloud& cloud_sensor);

  // Whether the last Update fitted the floor anew (true for the first frame), and why (empty
  // when the floor was reused): "first frame", "inliers fell to 31% (from 64%)", ...
  bool refitted() const { return refitted_; }
  const std::string& refit_reason() const { return refit_reason_; }
  // Frames since the last fit (0 right after one).
  int frames_since_fit() const { return frames_since_fit_; }
  const std::optional<FloorEstimate>& floor() const { return floor_; }

  // Forgets the kept floor: the next Update fits from scratch (e.g. after the sensor moved).
  void Reset();

 private:
  // The check's view of a cloud against `plane`: the fraction of checked points within the
  // inlier band and below it, and the least-squares plane of the inliers.
  struct Check {
    int points = 0;
    double inlier_fraction = 0.0;
    double below_fraction = 0.0;
    bool has_plane = false;
    Eigen::Vector4d plane = Eigen::Vector4d::Zero();
  };
  Check Measure(const PointCloud& cloud, const Eigen::Vector4d& plane);
  // Why the kept floor no longer fits `check`, or "" when it does.
  std::string Mismatch(const Check& check) const;

  FloorTrackerOptions options_;
  std::optional<FloorEstimate> floor_;
  Check reference_;  // the check on the frame of the last fit.
  bool refitted_ = false;
  std::string refit_reason_;
  int frames_since_fit_ = 0;
  std::vector<Eigen::Vector3f> sample_;  // reused buffers.
  std::vector<int> inliers_;
};

}  // namespace hpose

#endif  // HPOSE_CORE_DEPTH_FLOOR_TRACKER_H_
