#ifndef HPOSE_CORE_STEREO_STEREO_MARKER_OPTIONS_H_
#define HPOSE_CORE_STEREO_STEREO_MARKER_OPTIONS_H_

#include <array>
#include <string>

#include <Eigen/Core>

#include "core/common/status.h"
#include "core/stereo/color_segmenter.h"

namespace hpose {

// How the camera -> world transform is computed from the three landmarks.
enum class RigidFitMethod {
  kSvd,         // least-squares rotation (Horn/Umeyama); always a proper rotation.
  kClosedForm,  // the paper's appendix; exact without noise, not orthonormal with it.
  kCovariance,  // maximum likelihood under each landmark's triangulation covariance.
};
const char* RigidFitMethodName(RigidFitMethod method);  // "svd" | "closed_form" | "covariance"
// Fails with kInvalidArgument naming the accepted names.
Result<RigidFitMethod> ParseRigidFitMethod(const std::string& name);

// Options of the stereo-marker estimator; every default lives here.
struct StereoMarkerOptions {
  // Landmark centres in the world (field) frame, metres, z up; index = landmark id P0, P1, P2.
  // Defaults: the paper's layout P0 (0, 0, 0), P1 (-250, 400, 0), P2 (250, 400, 0) mm.
  std::array<Eigen::Vector3d, 3> landmarks_world_m = {Eigen::Vector3d(0.0, 0.0, 0.0),
                                                      Eigen::Vector3d(-0.25, 0.4, 0.0),
                                                      Eigen::Vector3d(0.25, 0.4, 0.0)};
  // Colour of the three landmarks (all the same colour; they are told apart by arrangement).
  HsvRange landmark_color{205.0, 250.0, 0.45, 1.0, 0.15, 1.0};
  // Colour of the tracked object (the ball).
  HsvRange object_color{8.0, 40.0, 0.5, 1.0, 0.15, 1.0};
  ColorSegmenterOptions segmentation;

  // A left/right pairing is plausible only when every pair is within this distance of its
  // epipolar line, pixels.
  double max_epipolar_error_px = 3.0;
  // Frames whose best fit leaves an RMS landmark residual above max_fit_rms_m plus
  // fit_rms_sigmas times the landmarks' RMS triangulation uncertainty are rejected, metres.
  double max_fit_rms_m = 0.04;
  double fit_rms_sigmas = 2.0;
  // The pairing/labelling is ambiguous (frame rejected) when the runner-up hypothesis fits
  // within this factor of the best one.
  double ambiguity_ratio = 1.5;
  // Triangles whose smallest vertex sine is below this count as collinear.
  double min_triangle_sine = 0.2;
  // The camera must be at least this far above the floor; it selects the mirror-image labelling.
  double min_camera_height_m = 0.05;
  // The object's left and right blobs must have areas within this factor of each other.
  double max_object_area_ratio = 3.0;
  // Radius of the landmark discs and of the ball, metres: the blob sizes a distance predicts.
  double landmark_radius_m = 0.06;
  double ball_radius_m = 0.035;
  // Candidate landmarks farther than this from the camera are ignored, metres.
  double max_landmark_range_m = 6.0;
  // Noise of a blob centroid, pixels: sets the triangulation covariance and with it the
  // tolerance of the layout test and the covariance-weighted fit.
  double centroid_sigma_px = 0.5;
  // Pairwise landmark distances must match the layout within this plus three sigma, metres.
  double layout_tolerance_m = 0.03;
  // A landmark whose blob covers less than this fraction of the area its distance, the fit's
  // orientation and its size predict (or is touched by another blob or cut by the border) is
  // taken as partly hidden: its weight in the fit is multiplied by occluded_weight...
  double occlusion_area_ratio = 0.88;
  double occluded_weight = 0.01;
  // ...and below this fraction the frame is rejected (too little of it is visible).
  double min_visible_fraction = 0.3;
  // A landmark's blob larger than this times the disc's predicted area (the disc grown by one
  // pixel all round) is not the landmark (a cloth or disc of its colour, or the landmark merged
  // with one): it is set aside and the landmarks are matched again without it.
  double max_landmark_area_ratio = 1.6;
  // The ball: its blob area within [1/max, max] times the area its distance predicts, its fill
  // of the bounding box at least min_ball_fill (a disc fills pi/4) and its aspect at most
  // max_ball_aspect, and once the pose is known
  // its centre within max_ball_height_error_m of ball_radius_m above the floor.
  double max_ball_area_factor = 2.2;
  double min_ball_fill = 0.62;
  double max_ball_aspect = 1.35;  // of its bounding box, in angle (pixels need not be square).
  double max_ball_height_error_m = 0.03;
  // The point of the robot reported as its position: by default the head's centre projected
  // on the floor. Set it to where the head sits relative to the depth template's origin
  // (below the torso centre), negated, so that both estimators report the same point:
  // reference = head on the floor + R(heading) * head_to_reference_m (robot frame: x forward,
  // y left), metres.
  Eigen::Vector2d head_to_reference_m = Eigen::Vector2d::Zero();
  // The covariance-weighted fit is the default: on the harder simulated frames of both rigs it
  // left a third of the closed form's mean robot error (docs/BENCHMARKS.md).
  RigidFitMethod method = RigidFitMethod::kCovariance;
  // Weight each landmark in the SVD least-squares fit by 1 / depth^4 (stereo depth variance grows
  // with depth^4), so that near landmarks count more.
  bool depth_weighted_fit = true;
  // Where the robot may be, world frame, metres. A labelling of the landmarks that puts the
  // robot elsewhere is discarded. The default keeps the robot on P0's side of the landmarks
  // (y <= 0), the assumption behind the paper's matching by image arrangement; it is what tells
  // the nearly equilateral triangle's vertices apart when triangulation is noisy.
  double robot_region_x_min_m = -1e9;
  double robot_region_x_max_m = 1e9;
  double robot_region_y_min_m = -1e9;
  double robot_region_y_max_m = 0.0;
};

// Fails with kInvalidArgument naming the first bad option.
Status ValidateStereoMarkerOptions(const StereoMarkerOptions& options);

// Reads options from an OpenCV FileStorage YAML/XML file; keys absent keep their defaults and
// unknown keys are errors. Keys: landmarks_world_m (3x3 matrix, one landmark per row),
// landmark_color and object_color ([hue_min_deg, hue_max_deg, sat_min, sat_max, val_min,
// val_max]), min_blob_area_px, max_epipolar_error_px, max_fit_rms_m, fit_rms_sigmas,
// ambiguity_ratio,
// min_triangle_sine, min_camera_height_m, max_object_area_ratio, method ("svd" |
// "closed_form" | "covariance"), depth_weighted_fit (0/1), robot_region_m ([x_min, x_max, y_min,
// y_max]), head_to_reference_m ([x, y]), and the numbers landmark_radius_m, ball_radius_m,
// max_landmark_range_m, centroid_sigma_px, layout_tolerance_m, occlusion_area_ratio,
// occluded_weight, min_visible_fraction, max_landmark_area_ratio, max_ball_area_factor,
// min_ball_fill, max_ball_aspect, max_ball_height_error_m. Fails with kNotFound, kDataLoss or
// kInvalidArgument naming the key.
Result<StereoMarkerOptions> LoadStereoMarkerOptions(const std::string& path);

}  // namespace hpose

#endif  // HPOSE_CORE_STEREO_STEREO_MARKER_OPTIONS_H_
