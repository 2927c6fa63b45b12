#include "core/search/pose_tracker.h"

#include <algorithm>
#include <utility>

#include "core/search/detection_order.h"
#include "core/search/humanoid_view.h"

namespace hpose {
namespace {

FloorTrackerOptions FloorOptions(const Estimator& estimator) {
  FloorTrackerOptions o;
  o.fit = estimator.options().floor_fit;
  return o;
}

}  // namespace

PoseTracker::PoseTracker(const Estimator* estimator)
    : estimator_(estimator), floor_(FloorOptions(*estimator)) {}

void PoseTracker::SetInitialPose(const Pose2D& pose) {
  initial_ = pose;
  initial_pending_ = true;
}

void PoseTracker::Reset() {
  prior_.reset();
  lost_frames_ = 0;
  floor_.Reset();
  initial_pending_ = initial_.has_value();
}

FramePrior PoseTracker::Context() {
  FramePrior context = prior_ ? *prior_ : FramePrior{};
  if (!prior_ && initial_pending_) {
    context.has_pose = true;
    context.pose = *initial_;
  }
  context.floor = &floor_;
  // Every offset off the floor in a stream's first frame and in the first frame without the
  // robot (it may have bent its knees), then one offset a frame in turn.
  context.height_offset_turn = prior_.has_value() || lost_frames_ == 0 ? -1 : lost_frames_ - 1;
  return context;
}

Result<Estimate> PoseTracker::EstimateDepth(const DepthImage& depth, const Intrinsics& intrinsics) {
  const FramePrior context = Context();
  return Keep(context, estimator_->EstimateDepth(depth, intrinsics, &context));
}

Result<Estimate> PoseTracker::EstimateCloud(const PointCloud& cloud_sensor) {
  const FramePrior context = Context();
  return Keep(context, estimator_->EstimateCloud(cloud_sensor, &context));
}

Result<Estimate> PoseTracker::Keep(const FramePrior& context, Result<Estimate> estimate) {
  prior_.reset();
  // 1, 2, ... up to the number of offsets off the floor, then 1 again.
  lost_frames_ = lost_frames_ % std::max(1, 2 * estimator_->options().height_offset_voxels) + 1;
  if (!estimate.ok()) return estimate;
  const HumanoidView humans = estimate->Humanoids();
  if (!humans.empty()) {
    lost_frames_ = 0;
    initial_pending_ = false;
    FramePrior p;
    p.has_pose = true;
    p.template_name = humans.front().best.template_name;
    p.pose = humans.front().best.pose;
    p.score = humans.front().best.score;
    p.height_offset_m = humans.front().best.height_offset_m;
    // The track is confirmed by this frame's evidence, or carried on from a confirmed one (or a
    // given initial pose) where the humanoid stands on the cluster the last pose held.
    const bool continues =
        context.has_pose && humans.front().best.cluster_index == estimate->tracking.held_cluster;
    p.hold_confirmed = (continues && context.hold_confirmed) ||
                       HumanoidEvidenceShare(humans.front().best) >=
                           estimator_->options().tracked_hold_min_evidence;
    prior_ = p;
  }
  return estimate;
}

}  // namespace hpose
