#ifndef HPOSE_CORE_STEREO_STEREO_ESTIMATOR_H_
#define HPOSE_CORE_STEREO_STEREO_ESTIMATOR_H_

#include <array>
#include <memory>

#include "core/common/status.h"
#include "core/stereo/color_segmenter.h"
#include "core/stereo/landmark_matcher.h"
#include "core/stereo/rgb_image.h"
#include "core/stereo/stereo_calibration.h"
#include "core/stereo/stereo_frame_result.h"
#include "core/stereo/stereo_marker_options.h"
#include "core/stereo/stereo_rig.h"

namespace hpose {

// Where the tracked object (the ball) was last seen, to continue its track.
struct StereoObjectPrior {
  Eigen::Vector3d world_m = Eigen::Vector3d::Zero();  // world frame, metres.
  double timestamp_s = 0.0;                           // when it was there.
  double max_speed_mps = 3.0;                         // how far it may have gone since, per second.
};

// The stereo-marker estimator, one frame pair at a time (no state; see StereoTracker for the
// temporal part): colour segmentation and labelling of the landmarks and the object in both
// images, distortion correction of the centroids only, left/right matching of the landmarks by
// their arrangement, triangulation, the camera -> world transform from the three landmarks
// (closed form and least squares), the robot's pose on the floor and the object's world
// position. Thread-compatible: Process is const and may run concurrently.
class StereoEstimator final {
 public:
  // Fails with kInvalidArgument when the calibration or the options are invalid.
  static Result<std::unique_ptr<StereoEstimator>> Create(const StereoCalibration& calibration,
                                                         const StereoMarkerOptions& options = {});

  // Processes one pair taken at `timestamp_s` (seconds, any epoch). A frame whose landmarks
  // cannot be used is not an error: the result says why in `status`/`reason`, and still
  // carries the object's camera-frame position when it was seen.
  // Fails with kInvalidArgument when an image is empty or malformed, the two images differ in
  // size, or their size differs from the calibration's stated image size.
  // With `object_prior` (e.g. StereoTracker::ObjectPrior), the ball is chosen among the
  // ball-like blob pairs also by how well it continues the track.
  Result<StereoFrameResult> Process(const RgbImage& left, const RgbImage& right, double timestamp_s,
                                    const StereoObjectPrior* object_prior = nullptr) const;

  const StereoMarkerOptions& options() const { return options_; }
  const StereoRig& rig() const { return *rig_; }

 private:
  StereoEstimator(std::unique_ptr<StereoRig> rig, ColorSegmenter segmenter,
                  const StereoMarkerOptions& options);

  // A left/right pair of object-coloured blobs that looks like the ball.
  struct ObjectCandidate {
    double score = 0.0;    // lower is more ball-like (size, epipolar error, roundness).
    double sigma_m = 0.0;  // triangulation uncertainty of its position.
    Eigen::Vector3d camera_m = Eigen::Vector3d::Zero();
    Eigen::Vector2d left_px = Eigen::Vector2d::Zero();
    Eigen::Vector2d right_px = Eigen::Vector2d::Zero();
    double epipolar_px = 0.0;
  };
  // The ball-like pairs of object-coloured blobs, best first; the best fills the result's
  // camera-frame object fields (none: object_reason).
  std::vector<ObjectCandidate> LocateObject(const std::vector<ColorBlob>& left,
                                            const std::vector<ColorBlob>& right,
                                            StereoFrameResult* result) const;
  static void SetObject(const ObjectCandidate& candidate, StereoFrameResult* result);

  // The area of landmark k's disc in the left and right images (pixels) when the camera sits
  // where `fit` puts it, and its perimeter (pixels) when asked; 0 for an image the whole disc
  // does not project into.
  std::array<double, 2> PredictedDiscAreaPx(const RigidFit& fit, int k,
                                            std::array<double, 2>* perimeter_px = nullptr) const;
  // Blobs too large for their landmark excluded from one frame before the match is given up.
  static constexpr int kMaxExcludedBlobs = 4;

  struct LandmarkVisibility {
    double visible_fraction = 1.0;  // blob area / predicted area, smaller of the two images.
    std::string note;               // why it is suspect; empty when it looks whole.
  };
  // Landmark k of `match` against the disc its fitted pose predicts, and its neighbours.
  LandmarkVisibility AssessLandmark(const LandmarkMatch& match, int k,
                                    const std::vector<ColorBlob>& left_landmarks,
                                    const std::vector<ColorBlob>& right_landmarks,
                                    const std::vector<ColorBlob>& left_objects,
                                    const std::vector<ColorBlob>& right_objects, int width,
                                    int height) const;

  std::unique_ptr<StereoRig> rig_;
  ColorSegmenter segmenter_;
  StereoMarkerOptions options_;
};

}  // namespace hpose

#endif  // HPOSE_CORE_STEREO_STEREO_ESTIMATOR_H_
