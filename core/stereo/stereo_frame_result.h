#ifndef HPOSE_CORE_STEREO_STEREO_FRAME_RESULT_H_
#define HPOSE_CORE_STEREO_STEREO_FRAME_RESULT_H_

#include <array>
#include <string>

#include <Eigen/Core>

#include "core/common/pose2d.h"
#include "core/stereo/rigid_fit.h"
#include "core/stereo/stereo_marker_options.h"

namespace hpose {

// Why a frame did or did not give a robot pose.
enum class StereoFrameStatus {
  kOk,
  kMissingLandmark,     // fewer than three landmark blobs in an image.
  kTooManyLandmarks,    // (no longer produced: extra blobs are sorted out by geometry).
  kNoConsistentMatch,   // no left/right pairing satisfies the epipolar and geometry tests.
  kAmbiguousMatch,      // two pairings or labellings fit about equally well.
  kCollinearLandmarks,  // the triangulated landmarks are (nearly) on one line.
  kPoorFit,             // the best fit leaves too large a residual or an impossible pose.
  kOccludedLandmark,    // a chosen landmark is mostly hidden or cut by the image border.
};
const char* StereoFrameStatusName(StereoFrameStatus status);  // e.g. "missing_landmark".

// Everything the stereo-marker estimator learns from one frame pair. Frames: camera = the left
// camera (x right, y down, z forward); world = the landmarks' field frame (z up). Metres.
struct StereoFrameResult {
  double timestamp_s = 0.0;
  StereoFrameStatus status = StereoFrameStatus::kOk;
  std::string reason;  // human-readable detail when status != kOk.

  int landmark_blobs_left = 0;
  int landmark_blobs_right = 0;
  // Distorted centroids and triangulated positions, indexed by landmark id (P0, P1, P2).
  std::array<Eigen::Vector2d, 3> landmark_left_px{};
  std::array<Eigen::Vector2d, 3> landmark_right_px{};
  std::array<Eigen::Vector3d, 3> landmark_camera_m{};
  double max_epipolar_error_px = 0.0;
  // Landmark selection: candidate left/right blob pairs, candidate triples matching the
  // layout, and the residual of the winning and of the best other hypothesis (the margin).
  int landmark_candidates = 0;
  int landmark_triples = 0;
  double landmark_best_rms_m = 0.0;
  double landmark_runner_up_rms_m = 0.0;  // inf when there was no other hypothesis.
  // Per landmark: visible fraction = blob area / area predicted from the fit (the smaller of
  // the two images), whether it was down-weighted as partly hidden, and why (empty if not).
  std::array<double, 3> landmark_visible_fraction{1.0, 1.0, 1.0};
  std::array<bool, 3> landmark_downweighted{false, false, false};
  // Landmark-coloured blobs set aside because they were much larger than the landmark the
  // pose predicted where they lie (options.max_landmark_area_ratio), and why; empty: none.
  std::string landmark_blobs_excluded;
  std::string landmark_notes;

  // Both camera -> world fits (rotation * x_camera + translation = x_world); `method` tells
  // which one the pose below uses. closed_form_ok is false when the closed form failed.
  RigidFit svd;
  RigidFit closed_form;
  bool closed_form_ok = false;
  RigidFit covariance;  // covariance-weighted fit (see RigidFitMethod::kCovariance).
  bool covariance_ok = false;
  RigidFitMethod method = RigidFitMethod::kSvd;
  // The fit of `method`.
  const RigidFit& fit() const {
    return method == RigidFitMethod::kSvd          ? svd
           : method == RigidFitMethod::kClosedForm ? closed_form
                                                   : covariance;
  }

  // The robot: the stereo head's centre (midpoint of the optical centres) projected onto the
  // floor, heading = the left optical axis projected onto the floor, counter-clockwise from
  // world +x. (The paper's theta = atan(r13 / r23) is measured from world +y instead.)
  // `robot` is the configured reference point of the robot (options.head_to_reference_m from
  // the head), `head` the head itself; they coincide by default.
  Pose2D robot;
  Pose2D head;
  double camera_height_m = 0.0;  // head centre above the floor.

  // The object: the most ball-like left/right pair of object-coloured blobs (epipolar match,
  // size for its distance, roundness, height above the floor once the pose is known).
  bool object_in_camera = false;  // triangulated.
  bool object_in_world = false;   // and the frame's pose is valid.
  std::string object_reason;      // why not, when not found.
  Eigen::Vector2d object_left_px = Eigen::Vector2d::Zero();
  Eigen::Vector2d object_right_px = Eigen::Vector2d::Zero();
  double object_epipolar_error_px = 0.0;
  Eigen::Vector3d object_camera_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d object_world_m = Eigen::Vector3d::Zero();

  bool ok() const { return status == StereoFrameStatus::kOk; }
};

}  // namespace hpose

#endif  // HPOSE_CORE_STEREO_STEREO_FRAME_RESULT_H_
