#include "core/stereo/landmark_matcher.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace hpose {
namespace {

constexpr std::array<std::array<int, 3>, 6> kPermutations = {
    {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};

// A left/right blob pair that could be one landmark.
struct Candidate {
  int left = 0, right = 0;
  Eigen::Vector3d camera_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  double sigma_m = 0.0;  // sqrt of the covariance's trace.
  double epipolar_px = 0.0;
};

int Extent(const ColorBlob& b) { return std::max(b.max_x - b.min_x, b.max_y - b.min_y) + 1; }

}  // namespace

LandmarkMatch MatchLandmarks(const StereoRig& rig, const std::vector<ColorBlob>& left,
                             const std::vector<ColorBlob>& right,
                             const StereoMarkerOptions& options) {
  LandmarkMatch best;
  std::ostringstream why;
  why.precision(3);
  if (left.size() < 3 || right.size() < 3) {
    const bool left_short = left.size() < 3;
    best.status = StereoFrameStatus::kMissingLandmark;
    why << (left_short ? "left" : "right") << " image shows "
        << (left_short ? left.size() : right.size()) << " landmark blob(s), need at least 3";
    best.reason = why.str();
    return best;
  }
  std::vector<Eigen::Vector2d> lpx, rpx;
  for (const ColorBlob& b : left) lpx.push_back(b.centroid_px);
  for (const ColorBlob& b : right) rpx.push_back(b.centroid_px);
  const std::vector<Eigen::Vector2d> ln = rig.Normalize(StereoSide::kLeft, lpx);
  const std::vector<Eigen::Vector2d> rn = rig.Normalize(StereoSide::kRight, rpx);
  const double fx = rig.calibration().left.camera_matrix(0, 0);

  // 1. Candidate stereo matches.
  std::vector<Candidate> cands;
  double best_epipolar_seen = std::numeric_limits<double>::infinity();
  int size_rejected = 0;
  for (size_t i = 0; i < left.size(); ++i) {
    for (size_t j = 0; j < right.size(); ++j) {
      const double epi = rig.EpipolarErrorPx(ln[i], rn[j]);
      best_epipolar_seen = std::min(best_epipolar_seen, epi);
      if (epi > options.max_epipolar_error_px) continue;
      bool depth_ok = false;
      const Eigen::Vector3d p = rig.Triangulate(ln[i], rn[j], &depth_ok);
      if (!depth_ok || p.norm() > options.max_landmark_range_m) continue;
      // A disc of the landmark's radius at this distance spans at most about this many pixels.
      const double diameter_px = 2 * options.landmark_radius_m * fx / p.norm();
      bool size_ok = true;
      for (const ColorBlob* b : {&left[i], &right[j]}) {
        const double extent = Extent(*b);
        size_ok &= extent <= 1.6 * diameter_px + 3 && extent >= 0.35 * diameter_px - 2;
      }
      const double area_ratio = static_cast<double>(std::max(left[i].area_px, right[j].area_px)) /
                                std::max(1, std::min(left[i].area_px, right[j].area_px));
      size_ok &= area_ratio <= 2.5;
      if (!size_ok) {
        ++size_rejected;
        continue;
      }
      Candidate c;
      c.left = static_cast<int>(i);
      c.right = static_cast<int>(j);
      c.camera_m = p;
      c.covariance = rig.TriangulationCovariance(ln[i], rn[j], options.centroid_sigma_px);
      c.sigma_m = std::sqrt(c.covariance.trace());
      c.epipolar_px = epi;
      cands.push_back(c);
    }
  }
  best.candidate_matches = static_cast<int>(cands.size());

  // 2. Triples matching the layout, every naming fitted.
  const std::vector<Eigen::Vector3d> world(options.landmarks_world_m.begin(),
                                           options.landmarks_world_m.end());
  std::array<double, 3> layout;  // sorted pairwise distances of the layout.
  layout[0] = (world[0] - world[1]).norm();
  layout[1] = (world[0] - world[2]).norm();
  layout[2] = (world[1] - world[2]).norm();
  std::sort(layout.begin(), layout.end());
  const Eigen::Vector3d head_in_camera = 0.5 * rig.RightCentreInLeft();
  double best_rms = std::numeric_limits<double>::infinity();
  double runner_up = std::numeric_limits<double>::infinity();
  bool any_collinear = false, any_fit = false, any_outside = false;
  const int n = static_cast<int>(cands.size());
  for (int a = 0; a < n; ++a) {
    for (int b = a + 1; b < n; ++b) {
      if (cands[a].left == cands[b].left || cands[a].right == cands[b].right) continue;
      for (int c = b + 1; c < n; ++c) {
        const Candidate* t[3] = {&cands[a], &cands[b], &cands[c]};
        if (t[2]->left == t[0]->left || t[2]->left == t[1]->left || t[2]->right == t[0]->right ||
            t[2]->right == t[1]->right) {
          continue;
        }
        std::array<double, 3> d = {(t[0]->camera_m - t[1]->camera_m).norm(),
                                   (t[0]->camera_m - t[2]->camera_m).norm(),
                                   (t[1]->camera_m - t[2]->camera_m).norm()};
        std::sort(d.begin(), d.end());
        const double sigma = std::max({t[0]->sigma_m, t[1]->sigma_m, t[2]->sigma_m});
        const double tolerance = options.layout_tolerance_m + 3.0 * sigma;
        bool layout_ok = true;
        for (int k = 0; k < 3; ++k) layout_ok &= std::abs(d[k] - layout[k]) <= tolerance;
        if (!layout_ok) continue;
        ++best.candidate_triples;
        if (TriangleMinSine(t[0]->camera_m, t[1]->camera_m, t[2]->camera_m) <
            options.min_triangle_sine) {
          any_collinear = true;
          continue;
        }
        for (const auto& naming : kPermutations) {  // landmark id k <-> t[naming[k]].
          std::vector<Eigen::Vector3d> camera(3);
          std::vector<double> weights;
          for (int k = 0; k < 3; ++k) {
            camera[k] = t[naming[k]]->camera_m;
            if (options.depth_weighted_fit) weights.push_back(1.0 / std::pow(camera[k].norm(), 4));
          }
          ++best.hypotheses_tested;
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
            best.max_epipolar_error_px = 0;
            for (int k = 0; k < 3; ++k) {
              const Candidate& ck = *t[naming[k]];
              best.left_index[k] = ck.left;
              best.right_index[k] = ck.right;
              best.camera_m[k] = ck.camera_m;
              best.camera_covariance[k] = ck.covariance;
              best.max_epipolar_error_px = std::max(best.max_epipolar_error_px, ck.epipolar_px);
            }
          } else if (rms < runner_up) {
            runner_up = rms;
          }
        }
      }
    }
  }
  best.best_rms_m = best_rms;
  best.runner_up_rms_m = runner_up;
  // The residual limit grows with the chosen landmarks' triangulation uncertainty: far
  // landmarks fit worse without being wrong.
  double limit = options.max_fit_rms_m;
  if (std::isfinite(best_rms)) {
    double variance = 0;
    for (int k = 0; k < 3; ++k) variance += best.camera_covariance[k].trace() / 3;
    limit += options.fit_rms_sigmas * std::sqrt(variance);
  }
  if (cands.size() < 3) {
    best.status =
        cands.empty() ? StereoFrameStatus::kNoConsistentMatch : StereoFrameStatus::kMissingLandmark;
    why << "only " << cands.size() << " landmark-coloured blob pair(s) agree with the epipolar "
        << "geometry and the landmark size (" << left.size() << " left, " << right.size()
        << " right blobs; best epipolar error " << best_epipolar_seen << " px, " << size_rejected
        << " pair(s) of the wrong size)";
  } else if (best.candidate_triples == 0) {
    best.status = StereoFrameStatus::kNoConsistentMatch;
    why << "no three of the " << cands.size()
        << " candidate landmarks are spaced like the landmark layout";
  } else if (!any_fit) {
    best.status =
        any_collinear ? StereoFrameStatus::kCollinearLandmarks : StereoFrameStatus::kPoorFit;
    why << (any_collinear ? "the triangulated landmarks are (nearly) collinear"
            : any_outside ? "every labelling of the landmarks puts the robot outside its region"
                          : "no labelling of the landmarks puts the camera above the floor");
  } else if (best_rms > limit) {
    best.status = StereoFrameStatus::kPoorFit;
    why << "best landmark fit leaves an RMS residual of " << best_rms * 1000 << " mm (limit "
        << limit * 1000 << " mm at this distance)";
  } else if (runner_up <= limit && runner_up < options.ambiguity_ratio * best_rms) {
    best.status = StereoFrameStatus::kAmbiguousMatch;
    why << "ambiguous landmark match: best RMS " << best_rms * 1000 << " mm, runner-up "
        << runner_up * 1000 << " mm (" << best.candidate_triples << " candidate triple(s))";
  } else {
    best.status = StereoFrameStatus::kOk;
  }
  best.reason = why.str();
  return best;
}

}  // namespace hpose
