#ifndef HPOSE_CORE_STEREO_LANDMARK_MATCHER_H_
#define HPOSE_CORE_STEREO_LANDMARK_MATCHER_H_

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/stereo/rigid_fit.h"
#include "core/stereo/stereo_frame_result.h"
#include "core/stereo/stereo_marker_options.h"
#include "core/stereo/stereo_rig.h"

namespace hpose {

// The outcome of matching three same-coloured landmarks between the two images and naming them.
struct LandmarkMatch {
  StereoFrameStatus status = StereoFrameStatus::kOk;
  std::string reason;
  std::array<int, 3> left_index{};   // for landmark id k, the index of its left image point.
  std::array<int, 3> right_index{};  // and of its right image point.
  std::array<Eigen::Vector3d, 3> camera_m{};  // triangulated, left camera frame, by id.
  RigidFit svd;                               // world_from_camera of the winning hypothesis.
  double max_epipolar_error_px = 0.0;
  double runner_up_rms_m = 0.0;  // residual of the best other hypothesis (inf when none).
  int hypotheses_tested = 0;
};

// Matching by arrangement. Every pairing of the three left points with the three right points
// whose epipolar errors are all within the limit is triangulated; every naming of the three
// triangulated points as P0, P1, P2 is fitted to the known field layout (least squares); a
// naming must put the camera above the floor, which fixes the mirror image. The hypothesis
// with the smallest residual wins; the frame is rejected as ambiguous when another one fits
// within options.ambiguity_ratio of it, as collinear when the triangulated points are nearly
// on a line, and as a poor fit when even the best residual exceeds options.max_fit_rms_m.
// `left_normalized` and `right_normalized` hold exactly three undistorted normalised points.
LandmarkMatch MatchLandmarks(const StereoRig& rig,
                             const std::vector<Eigen::Vector2d>& left_normalized,
                             const std::vector<Eigen::Vector2d>& right_normalized,
                             const StereoMarkerOptions& options);

}  // namespace hpose

#endif  // HPOSE_CORE_STEREO_LANDMARK_MATCHER_H_
