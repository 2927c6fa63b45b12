#ifndef HPOSE_CORE_STEREO_LANDMARK_MATCHER_H_
#define HPOSE_CORE_STEREO_LANDMARK_MATCHER_H_

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/stereo/color_segmenter.h"
#include "core/stereo/rigid_fit.h"
#include "core/stereo/stereo_frame_result.h"
#include "core/stereo/stereo_marker_options.h"
#include "core/stereo/stereo_rig.h"

namespace hpose {

// The outcome of choosing the three landmarks among all landmark-coloured blobs of a pair.
struct LandmarkMatch {
  StereoFrameStatus status = StereoFrameStatus::kOk;
  std::string reason;
  std::array<int, 3> left_index{};            // for landmark id k, the index of its left blob.
  std::array<int, 3> right_index{};           // and of its right blob.
  std::array<Eigen::Vector3d, 3> camera_m{};  // triangulated, left camera frame, by id.
  std::array<Eigen::Matrix3d, 3> camera_covariance{};  // of camera_m, m^2.
  RigidFit svd;  // world_from_camera of the winning hypothesis (options' SVD weighting).
  double max_epipolar_error_px = 0.0;
  double best_rms_m = 0.0;       // landmark residual of the winner.
  double runner_up_rms_m = 0.0;  // of the best other hypothesis (inf when none).
  int candidate_matches = 0;     // left/right blob pairs that could be a landmark.
  int candidate_triples = 0;     // triples of them whose distances match the layout.
  int hypotheses_tested = 0;     // namings of those triples that were fitted.
};

// Landmark selection by geometry. Every landmark-coloured blob of the left image is paired with
// every one of the right image; a pair is a candidate when it is within
// options.max_epipolar_error_px of the epipolar line, triangulates in front of both cameras
// within options.max_landmark_range_m, and its blob size suits a disc of
// options.landmark_radius_m at that distance. Triples of candidates (distinct blobs) whose
// pairwise distances match the known layout within the triangulation uncertainty are named
// P0, P1, P2 in every way and fitted (least squares); a naming must put the camera above the
// floor and the robot in its region. The smallest residual wins; the frame is rejected as
// ambiguous when another hypothesis fits within options.ambiguity_ratio of it, as a poor fit
// when even the best exceeds options.max_fit_rms_m plus options.fit_rms_sigmas times the
// landmarks' RMS triangulation uncertainty, and as missing/no-match otherwise, always
// with a reason.
LandmarkMatch MatchLandmarks(const StereoRig& rig, const std::vector<ColorBlob>& left,
                             const std::vector<ColorBlob>& right,
                             const StereoMarkerOptions& options);

}  // namespace hpose

#endif  // HPOSE_CORE_STEREO_LANDMARK_MATCHER_H_
