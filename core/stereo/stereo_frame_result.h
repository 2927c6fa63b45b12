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
  kTooManyLandmarks,    // more than three landmark blobs in an image.
  kNoConsistentMatch,   // no left/right pairing satisfies the epipolar and geometry tests.
  kAmbiguousMatch,      // two pairings or labellings fit about equally well.
  kCollinearLandmarks,  // the triangulated landmarks are (nearly) on one line.
  kPoorFit,             // the best fit leaves too large a residual or an impossible pose.
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

  // Both camera -> world fits (rotation * x_camera + translation = x_world); `method` tells
  // which one the pose below uses. closed_form_ok is false when the closed form failed.
  RigidFit svd;
  RigidFit closed_form;
  bool closed_form_ok = false;
  RigidFitMethod method = RigidFitMethod::kSvd;

  // The robot: the stereo head's centre (midpoint of the optical centres) projected onto the
  // floor, heading = the left optical axis projected onto the floor, counter-clockwise from
  // world +x. (The paper's theta = atan(r13 / r23) is measured from world +y instead.)
  Pose2D robot;
  double camera_height_m = 0.0;  // head centre above the floor.

  // The object (largest blob of the object colour matched across the pair).
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
