#include "core/depth/floor_tracker.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

#include "core/depth/floor_plane.h"

namespace hpose {
namespace {

// Fewer checked inliers than this cannot vouch for the kept floor.
constexpr int kMinCheckInliers = 30;

std::string Format(const char* format, double a, double b) {
  char text[96];
  std::snprintf(text, sizeof(text), format, a, b);
  return text;
}

// Every k-th point of the cloud (a square pixel lattice when organised), finite points only,
// about `target` of them when the cloud is dense.
void SamplePoints(const PointCloud& cloud, int target, std::vector<Eigen::Vector3f>* out) {
  out->clear();
  const size_t ratio = std::max<size_t>(1, cloud.size() / std::max(1, target));
  if (cloud.organised() && ratio > 1) {
    const int stride = std::max(1, static_cast<int>(std::lround(std::sqrt(double(ratio)))));
    for (int v = stride / 2; v < cloud.height; v += stride) {
      const Eigen::Vector3f* row = cloud.points.data() + static_cast<size_t>(v) * cloud.width;
      for (int u = stride / 2; u < cloud.width; u += stride) {
        if (row[u].allFinite()) out->push_back(row[u]);
      }
    }
    return;
  }
  for (size_t i = 0; i < cloud.size(); i += ratio) {
    if (cloud.points[i].allFinite()) out->push_back(cloud.points[i]);
  }
}

}  // namespace

FloorTracker::FloorTracker(FloorTrackerOptions options) : options_(std::move(options)) {}

void FloorTracker::Reset() {
  floor_.reset();
  frames_since_fit_ = 0;
}

FloorTracker::Check FloorTracker::Measure(const PointCloud& cloud, const Eigen::Vector4d& plane) {
  Check c;
  SamplePoints(cloud, std::max(1, options_.check_points), &sample_);
  c.points = static_cast<int>(sample_.size());
  if (sample_.empty()) return c;
  const double threshold = options_.fit.distance_threshold_m;
  SelectFloorInliers(sample_, plane, threshold, &inliers_);
  c.inlier_fraction = static_cast<double>(inliers_.size()) / c.points;
  c.below_fraction =
      static_cast<double>(CountBelowFloorPlane(sample_, plane, threshold)) / c.points;
  if (static_cast<int>(inliers_.size()) >= kMinCheckInliers) {
    c.has_plane = FitFloorPlaneLeastSquares(sample_, inliers_, threshold, &c.plane);
  }
  return c;
}

std::string FloorTracker::Mismatch(const Check& c) const {
  if (!c.has_plane) {
    return "only " + std::to_string(static_cast<int>(c.inlier_fraction * c.points)) +
           " checked points on the floor";
  }
  if (c.inlier_fraction < options_.min_inlier_ratio * reference_.inlier_fraction) {
    return Format("inliers fell to %.0f%% (from %.0f%%)", 100.0 * c.inlier_fraction,
                  100.0 * reference_.inlier_fraction);
  }
  if (c.below_fraction > options_.max_below_fraction) {
    return Format("%.1f%% of the points lie below the floor (limit %.1f%%)",
                  100.0 * c.below_fraction, 100.0 * options_.max_below_fraction);
  }
  const double cos_tilt = std::clamp(c.plane.head<3>().dot(reference_.plane.head<3>()), -1.0, 1.0);
  const double tilt = std::acos(cos_tilt);
  if (tilt > options_.max_tilt_change_rad) {
    return Format("the floor tilted by %.2f deg (limit %.2f deg)", tilt * 180.0 / M_PI,
                  options_.max_tilt_change_rad * 180.0 / M_PI);
  }
  const double height_change = std::abs(c.plane[3] - reference_.plane[3]);
  if (height_change > options_.max_height_change_m) {
    return Format("the sensor height changed by %.1f mm (limit %.1f mm)", 1e3 * height_change,
                  1e3 * options_.max_height_change_m);
  }
  if (options_.max_reuse_frames > 0 && frames_since_fit_ >= options_.max_reuse_frames) {
    return "reused for " + std::to_string(frames_since_fit_) + " frames";
  }
  return "";
}

Result<FloorEstimate> FloorTracker::Update(const PointCloud& cloud_sensor) {
  if (cloud_sensor.empty()) {
    return MakeError(ErrorCode::kInvalidArgument, "floor tracker: the cloud is empty");
  }
  if (options_.check_points < 1) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "floor tracker options: check_points must be >= 1");
  }
  refitted_ = true;
  refit_reason_ = "first frame";
  if (floor_.has_value()) {
    const Check check = Measure(cloud_sensor, floor_->plane_sensor);
    refit_reason_ = Mismatch(check);
    if (refit_reason_.empty()) {
      refitted_ = false;
      ++frames_since_fit_;
      return *floor_;
    }
  }
  Result<FloorEstimate> fitted = FitFloor(cloud_sensor, options_.fit);
  frames_since_fit_ = 0;
  if (!fitted.ok()) {
    floor_.reset();
    return fitted;
  }
  floor_ = *fitted;
  reference_ = Measure(cloud_sensor, fitted->plane_sensor);
  if (!reference_.has_plane) {
    // Too few checked points on this floor to vouch for it later: fit every frame meanwhile.
    floor_.reset();
  }
  return fitted;
}

}  // namespace hpose
