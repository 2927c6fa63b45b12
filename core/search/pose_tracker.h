#ifndef HPOSE_CORE_SEARCH_POSE_TRACKER_H_
#define HPOSE_CORE_SEARCH_POSE_TRACKER_H_

#include <optional>

#include "core/common/status.h"
#include "core/depth/floor_tracker.h"
#include "core/search/estimator.h"

namespace hpose {

// Estimates the frames of one stream in order, each seeded with the humanoid pose of the frame
// before (Estimator's FramePrior) and with the stream's floor kept while it still fits
// (FloorTracker). The search starts from where the robot was, a heading the frame cannot
// tell from its flip keeps to the one before, a pose whose heading the frame confirms needs no
// runner-up heading searched for (Candidate::heading_confirmed), and the cluster the robot stood on
// passes from the lower tracked_score_threshold (a humanoid walking away scores less). Every frame
// is still searched globally: a robot that was carried away, or lost and found again, comes back in
// the same frame. A frame without a humanoid (or an error) drops the pose: the next search starts
// cold. While the robot is lost, a frame in which nothing passes tries the templates off the floor
// (EstimatorOptions::height_offset_voxels) at every offset in the stream's first frame and the
// first frame without the robot, then at one offset a frame, in turn: such a frame costs about
// twice the search on the floor alone rather than up to five times in one frame of four, and a
// robot standing lower or higher than its template (bent knees) is found within as many frames as
// there are offsets (four by default), then tracked at its offset. Not thread-safe: one stream,
// one tracker.
class PoseTracker {
 public:
  // `estimator` must outlive the tracker.
  explicit PoseTracker(const Estimator* estimator);

  Result<Estimate> EstimateDepth(const DepthImage& depth, const Intrinsics& intrinsics);
  Result<Estimate> EstimateCloud(const PointCloud& cloud_sensor);

  // Where the robot is expected when the stream starts (ground frame), like a navigation stack's
  // initial pose: until the robot is first found, and again after each Reset, frames are
  // estimated as if the frame before had seen it there (FramePrior with an empty
  // template_name), so its cluster passes from tracked_score_threshold. A robot too far to
  // reach score_threshold (and so never found by a cold search) is found from the first frame.
  // theta only breaks front/back ties.
  void SetInitialPose(const Pose2D& pose);

  // Forgets the previous frames (e.g. when the source restarts): pose and floor. An initial
  // pose applies again.
  void Reset();
  // The pose the next frame starts from, if any.
  const std::optional<FramePrior>& prior() const { return prior_; }

 private:
  // Keeps the pose `estimate` gives for the next frame; `context` is what it started from.
  Result<Estimate> Keep(const FramePrior& context, Result<Estimate> estimate);

  FramePrior Context();

  const Estimator* estimator_;
  std::optional<FramePrior> prior_;  // with has_pose.
  std::optional<Pose2D> initial_;    // SetInitialPose's.
  bool initial_pending_ = false;     // the robot was not found since it was set or Reset.
  // 0 at the stream's start and while the robot is found; else frames in a row without a
  // humanoid (or with an error), counted from 1 up to the number of offsets off the floor
  // (FramePrior::height_offset_turn) and around again.
  int lost_frames_ = 0;
  FloorTracker floor_;
};

}  // namespace hpose

#endif  // HPOSE_CORE_SEARCH_POSE_TRACKER_H_
