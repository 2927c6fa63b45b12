#include "core/search/pose_tracker.h"

#include <utility>

namespace hpose {

Result<Estimate> PoseTracker::EstimateDepth(const DepthImage& depth, const Intrinsics& intrinsics) {
  return Keep(estimator_->EstimateDepth(depth, intrinsics, prior_ ? &*prior_ : nullptr));
}

Result<Estimate> PoseTracker::EstimateCloud(const PointCloud& cloud_sensor) {
  return Keep(estimator_->EstimateCloud(cloud_sensor, prior_ ? &*prior_ : nullptr));
}

Result<Estimate> PoseTracker::Keep(Result<Estimate> estimate) {
  prior_.reset();
  if (!estimate.ok()) return estimate;
  const std::vector<Detection> humans = estimate->Humanoids();
  if (!humans.empty())
    prior_ = FramePrior{humans.front().best.template_name, humans.front().best.pose};
  return estimate;
}

}  // namespace hpose
