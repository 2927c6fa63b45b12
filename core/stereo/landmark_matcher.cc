#include "core/stereo/landmark_matcher.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <sstream>

namespace hpose {
namespace {

constexpr std::array<std::array<int, 3>, 6> kPermutations = {
    {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};

}  // namespace

LandmarkMatch MatchLandmarks(const StereoRig& rig,
                             const std::vector<Eigen::Vector2d>& left_normalized,
                             const std::vector<Eigen::Vector2d>& right_normalized,
                             const StereoMarkerOptions& options) {
  assert(left_normalized.size() == 3 && right_normalized.size() == 3);
  LandmarkMatch best;
  best.status = StereoFrameStatus::kNoConsistentMatch;
  double best_rms = std::numeric_limits<double>::infinity();
  double runner_up = std::numeric_limits<double>::infinity();
  double best_epipolar_seen = std::numeric_limits<double>::infinity();
  bool any_pairing = false, any_collinear = false, any_fit = false, any_outside = false;
  const std::vector<Eigen::Vector3d> world(options.landmarks_world_m.begin(),
                                           options.landmarks_world_m.end());
  const Eigen::Vector3d head_in_camera = 0.5 * rig.RightCentreInLeft();

  for (const auto& pair : kPermutations) {  // left point i <-> right point pair[i].
    double max_epi = 0.0;
    for (int i = 0; i < 3; ++i) {
      max_epi =
          std::max(max_epi, rig.EpipolarErrorPx(left_normalized[i], right_normalized[pair[i]]));
    }
    best_epipolar_seen = std::min(best_epipolar_seen, max_epi);
    if (max_epi > options.max_epipolar_error_px) continue;
    std::array<Eigen::Vector3d, 3> points;
    bool depth_ok = true;
    for (int i = 0; i < 3 && depth_ok; ++i) {
      points[i] = rig.Triangulate(left_normalized[i], right_normalized[pair[i]], &depth_ok);
    }
    if (!depth_ok) continue;
    any_pairing = true;
    if (TriangleMinSine(points[0], points[1], points[2]) < options.min_triangle_sine) {
      any_collinear = true;
      continue;
    }
    for (const auto& naming : kPermutations) {  // landmark id k <-> triangulated point naming[k].
      std::vector<Eigen::Vector3d> camera(3);
      for (int k = 0; k < 3; ++k) camera[k] = points[naming[k]];
      ++best.hypotheses_tested;
      std::vector<double> weights;
      if (options.depth_weighted_fit) {
        for (int k = 0; k < 3; ++k) weights.push_back(1.0 / std::pow(camera[k].norm(), 4));
      }
      Result<RigidFit> fit = FitRigidSvd(camera, world, options.min_triangle_sine, weights);
      if (!fit.ok()) continue;
      const Eigen::Vector3d head = fit->rotation * head_in_camera + fit->translation;
      if (head.z() < options.min_camera_height_m) continue;  // the mirror image.
      if (head.x() < options.robot_region_x_min_m || head.x() > options.robot_region_x_max_m ||
          head.y() < options.robot_region_y_min_m || head.y() > options.robot_region_y_max_m) {
        any_outside = true;
        continue;
      }
      any_fit = true;
      const double rms = fit->rms_residual_m;
      if (rms < best_rms) {
        runner_up = best_rms;
        best_rms = rms;
        best.svd = *fit;
        best.max_epipolar_error_px = max_epi;
        for (int k = 0; k < 3; ++k) {
          best.left_index[k] = naming[k];
          best.right_index[k] = pair[naming[k]];
          best.camera_m[k] = camera[k];
        }
      } else if (rms < runner_up) {
        runner_up = rms;
      }
    }
  }
  best.runner_up_rms_m = runner_up;
  std::ostringstream why;
  why.precision(3);
  if (!any_pairing) {
    best.status = StereoFrameStatus::kNoConsistentMatch;
    why << "no left/right pairing of the landmarks within " << options.max_epipolar_error_px
        << " px of the epipolar lines (best " << best_epipolar_seen << " px)";
  } else if (!any_fit) {
    best.status =
        any_collinear ? StereoFrameStatus::kCollinearLandmarks : StereoFrameStatus::kPoorFit;
    why << (any_collinear ? "the triangulated landmarks are (nearly) collinear"
            : any_outside ? "every labelling of the landmarks puts the robot outside its region"
                          : "no labelling of the landmarks puts the camera above the floor");
  } else if (best_rms > options.max_fit_rms_m) {
    best.status = StereoFrameStatus::kPoorFit;
    why << "best landmark fit leaves an RMS residual of " << best_rms * 1000 << " mm (limit "
        << options.max_fit_rms_m * 1000 << " mm)";
  } else if (runner_up <= options.max_fit_rms_m && runner_up < options.ambiguity_ratio * best_rms) {
    best.status = StereoFrameStatus::kAmbiguousMatch;
    why << "ambiguous landmark match: best RMS " << best_rms * 1000 << " mm, runner-up "
        << runner_up * 1000 << " mm";
  } else {
    best.status = StereoFrameStatus::kOk;
  }
  best.reason = why.str();
  return best;
}

}  // namespace hpose
