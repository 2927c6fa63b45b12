#include "core/stereo/stereo_estimator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <Eigen/Geometry>

#include "core/stereo/landmark_matcher.h"
#include "core/stereo/rigid_fit.h"

namespace hpose {
namespace {

constexpr int kLandmarkClass = 0;
constexpr int kObjectClass = 1;

std::string SizeText(const RgbImage& image) {
  return std::to_string(image.width) + "x" + std::to_string(image.height);
}

}  // namespace

Result<std::unique_ptr<StereoEstimator>> StereoEstimator::Create(
    const StereoCalibration& calibration, const StereoMarkerOptions& options) {
  Status valid = ValidateStereoMarkerOptions(options);
  if (!valid.ok()) return valid.error();
  auto rig = StereoRig::Create(calibration);
  if (!rig.ok()) return rig.error();
  auto segmenter =
      ColorSegmenter::Create({options.landmark_color, options.object_color}, options.segmentation);
  if (!segmenter.ok()) return segmenter.error();
  return std::unique_ptr<StereoEstimator>(
      new StereoEstimator(std::move(rig).value(), std::move(segmenter).value(), options));
}

StereoEstimator::StereoEstimator(std::unique_ptr<StereoRig> rig, ColorSegmenter segmenter,
                                 const StereoMarkerOptions& options)
    : rig_(std::move(rig)), segmenter_(std::move(segmenter)), options_(options) {}

Result<StereoFrameResult> StereoEstimator::Process(const RgbImage& left, const RgbImage& right,
                                                   double timestamp_s,
                                                   const StereoObjectPrior* object_prior) const {
  if (!left.valid() || !right.valid()) {
    return MakeError(ErrorCode::kInvalidArgument,
                     std::string(left.valid() ? "right" : "left") +
                         " image is empty or its buffer does not match its size");
  }
  if (left.width != right.width || left.height != right.height) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "left image is " + SizeText(left) + " but right image is " + SizeText(right));
  }
  const StereoCalibration& cal = rig_->calibration();
  if (cal.image_width > 0 && (left.width != cal.image_width || left.height != cal.image_height)) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "images are " + SizeText(left) + " but the calibration is for " +
                         std::to_string(cal.image_width) + "x" + std::to_string(cal.image_height));
  }
  if (!std::isfinite(timestamp_s)) {
    return MakeError(ErrorCode::kInvalidArgument, "frame timestamp is not finite");
  }

  StereoFrameResult result;
  result.timestamp_s = timestamp_s;
  result.method = options_.method;
  const std::vector<std::vector<ColorBlob>> lb = segmenter_.Segment(left);
  const std::vector<std::vector<ColorBlob>> rb = segmenter_.Segment(right);
  const std::vector<ObjectCandidate> objects =
      LocateObject(lb[kObjectClass], rb[kObjectClass], &result);

  std::vector<ColorBlob> ll = lb[kLandmarkClass];
  std::vector<ColorBlob> rl = rb[kLandmarkClass];
  result.landmark_blobs_left = static_cast<int>(ll.size());
  result.landmark_blobs_right = static_cast<int>(rl.size());
  // A chosen blob much larger than the disc the fitted pose predicts where it lies is not that
  // landmark (a landmark-coloured cloth, or a landmark merged with one); the landmarks are
  // matched again without it, so a distractor that happened to complete the layout within the
  // triangulation tolerance (far away, where that tolerance is wide) cannot stay chosen.
  LandmarkMatch match;
  std::string excluded;
  for (int round = 0;; ++round) {
    match = MatchLandmarks(*rig_, ll, rl, options_);
    if (match.status != StereoFrameStatus::kOk || round == kMaxExcludedBlobs) break;
    int worst_k = -1, worst_side = 0;
    double worst_ratio = options_.max_landmark_area_ratio;
    for (int k = 0; k < 3; ++k) {
      std::array<double, 2> perimeter{};
      const std::array<double, 2> predicted = PredictedDiscAreaPx(match.svd, k, &perimeter);
      for (int side = 0; side < 2; ++side) {
        if (predicted[side] <= 1) continue;
        const ColorBlob& blob = side == 0 ? ll[match.left_index[k]] : rl[match.right_index[k]];
        // The disc grown by one pixel all round: blur, demosaicing and JPEG widen a blob by
        // about that much, which matters for the few-pixel-high discs far away.
        const double ratio = blob.area_px / (predicted[side] + perimeter[side]);
        if (ratio > worst_ratio) {
          worst_ratio = ratio;
          worst_k = k;
          worst_side = side;
        }
      }
    }
    if (worst_k < 0) break;
    std::vector<ColorBlob>& blobs = worst_side == 0 ? ll : rl;
    const int index = worst_side == 0 ? match.left_index[worst_k] : match.right_index[worst_k];
    std::ostringstream note;
    note.precision(3);
    note << (excluded.empty() ? "" : "; ") << "a " << (worst_side == 0 ? "left" : "right")
         << " blob at (" << blobs[index].centroid_px.x() << ", " << blobs[index].centroid_px.y()
         << ") is " << worst_ratio << " times the area of landmark P" << worst_k
         << " there: not a landmark";
    excluded += note.str();
    blobs.erase(blobs.begin() + index);
  }
  result.landmark_blobs_excluded = excluded;
  result.status = match.status;
  result.reason = match.reason;
  if (match.status != StereoFrameStatus::kOk && !excluded.empty()) {
    result.reason += " (after excluding blobs too large for a landmark: " + excluded + ")";
  }
  result.landmark_candidates = match.candidate_matches;
  result.landmark_triples = match.candidate_triples;
  result.landmark_best_rms_m = match.best_rms_m;
  result.landmark_runner_up_rms_m = match.runner_up_rms_m;
  if (match.status != StereoFrameStatus::kOk &&
      match.status != StereoFrameStatus::kAmbiguousMatch &&
      match.status != StereoFrameStatus::kPoorFit) {
    return result;
  }
  if (match.hypotheses_tested == 0 || !std::isfinite(match.svd.rms_residual_m)) return result;
  for (int k = 0; k < 3; ++k) {
    result.landmark_left_px[k] = ll[match.left_index[k]].centroid_px;
    result.landmark_right_px[k] = rl[match.right_index[k]].centroid_px;
    result.landmark_camera_m[k] = match.camera_m[k];
  }
  result.max_epipolar_error_px = match.max_epipolar_error_px;
  result.svd = match.svd;
  if (match.status != StereoFrameStatus::kOk) return result;

  // Occlusion: each chosen landmark's blobs against what the fit predicts.
  std::array<double, 3> weight{1.0, 1.0, 1.0};
  std::ostringstream notes;
  notes.precision(2);
  for (int k = 0; k < 3; ++k) {
    const LandmarkVisibility v = AssessLandmark(match, k, ll, rl, lb[kObjectClass],
                                                rb[kObjectClass], left.width, left.height);
    result.landmark_visible_fraction[k] = v.visible_fraction;
    if (v.visible_fraction < options_.min_visible_fraction) {
      result.status = StereoFrameStatus::kOccludedLandmark;
      std::ostringstream why;
      why.precision(2);
      why << "landmark P" << k << " is mostly hidden: " << v.visible_fraction * 100
          << " % of its predicted area visible (limit " << options_.min_visible_fraction * 100
          << " %)";
      result.reason = why.str();
      return result;
    }
    if (!v.note.empty()) {
      result.landmark_downweighted[k] = true;
      weight[k] = options_.occluded_weight;
      notes << (notes.tellp() > 0 ? "; " : "") << "P" << k << " " << v.note;
    }
  }
  result.landmark_notes = notes.str();
  const std::vector<Eigen::Vector3d> camera(match.camera_m.begin(), match.camera_m.end());
  const std::vector<Eigen::Vector3d> world(options_.landmarks_world_m.begin(),
                                           options_.landmarks_world_m.end());
  std::vector<double> weights(3, 1.0);
  std::vector<Eigen::Matrix3d> covariances(3);
  for (int k = 0; k < 3; ++k) {
    if (options_.depth_weighted_fit) weights[k] = 1.0 / std::pow(camera[k].norm(), 4);
    weights[k] *= weight[k];
    covariances[k] = match.camera_covariance[k] / weight[k] +
                     Eigen::Matrix3d::Identity() * 1e-10;  // keeps it positive definite.
  }
  if (!result.landmark_notes.empty()) {
    Result<RigidFit> refit = FitRigidSvd(camera, world, options_.min_triangle_sine, weights);
    if (refit.ok()) result.svd = *refit;
  }
  Result<RigidFit> cov = FitRigidCovariance(camera, world, covariances, options_.min_triangle_sine);
  result.covariance_ok = cov.ok();
  if (cov.ok()) result.covariance = *cov;
  Result<RigidFit> closed =
      FitRigidClosedForm(match.camera_m, options_.landmarks_world_m, options_.min_triangle_sine);
  result.closed_form_ok = closed.ok();
  if (closed.ok()) result.closed_form = *closed;

  if ((options_.method == RigidFitMethod::kClosedForm && !closed.ok()) ||
      (options_.method == RigidFitMethod::kCovariance && !cov.ok())) {
    result.status = StereoFrameStatus::kCollinearLandmarks;
    result.reason = (closed.ok() ? cov.error() : closed.error()).message;
    return result;
  }
  const RigidFit& fit = result.fit();
  const Eigen::Vector3d head = fit.rotation * (0.5 * rig_->RightCentreInLeft()) + fit.translation;
  const Eigen::Vector3d axis = fit.rotation.col(2);  // optical axis in the world frame.
  if (std::hypot(axis.x(), axis.y()) < 1e-3) {
    result.status = StereoFrameStatus::kPoorFit;
    result.reason = "the optical axis is vertical; the heading is undefined";
    return result;
  }
  result.head.x = head.x();
  result.head.y = head.y();
  result.head.theta = NormalizeAngle(std::atan2(axis.y(), axis.x()));
  const Eigen::Vector2d reference =
      Eigen::Vector2d(head.x(), head.y()) +
      Eigen::Rotation2Dd(result.head.theta) * options_.head_to_reference_m;
  result.robot = Pose2D{reference.x(), reference.y(), result.head.theta};
  result.camera_height_m = head.z();
  if (!objects.empty()) {
    // Among the ball-like pairs: on the floor (centre about one radius up), and, given a
    // prior from the track, reachable from where the ball was.
    const ObjectCandidate* best = nullptr;
    double best_score = std::numeric_limits<double>::infinity();
    std::string why_not;
    for (const ObjectCandidate& c : objects) {
      const Eigen::Vector3d world_object = fit.rotation * c.camera_m + fit.translation;
      const double height_error = std::abs(world_object.z() - options_.ball_radius_m);
      if (height_error > options_.max_ball_height_error_m + std::min(3.0 * c.sigma_m, 0.1)) {
        if (why_not.empty()) {
          std::ostringstream why;
          why.precision(3);
          why << "the most ball-like blob pair is " << world_object.z() * 1000
              << " mm above the floor, not a ball of radius " << options_.ball_radius_m * 1000
              << " mm on it";
          why_not = why.str();
        }
        continue;
      }
      double score = c.score;
      if (object_prior != nullptr) {
        const double dt = std::max(0.0, timestamp_s - object_prior->timestamp_s);
        const double reach = 0.05 + 3.0 * c.sigma_m + object_prior->max_speed_mps * dt;
        score += (world_object - object_prior->world_m).head<2>().norm() / reach;
      }
      if (score < best_score) {
        best_score = score;
        best = &c;
        result.object_world_m = world_object;
      }
    }
    if (best != nullptr) {
      SetObject(*best, &result);
      result.object_in_world = true;
    } else {
      result.object_reason = why_not;
      result.object_in_camera = false;
    }
  } else if (result.object_reason.empty()) {
    result.object_reason = "object not seen";
  }
  return result;
}

std::array<double, 2> StereoEstimator::PredictedDiscAreaPx(
    const RigidFit& fit, int k, std::array<double, 2>* perimeter_px) const {
  // The disc's rim in the left camera frame, from the fit (camera = R^T (world - t)).
  const Eigen::Matrix3d rt = fit.rotation.transpose();
  const Eigen::Vector3d centre = options_.landmarks_world_m[k];
  constexpr int kRim = 24;
  std::array<std::vector<Eigen::Vector2d>, 2> rim;
  for (int i = 0; i < kRim; ++i) {
    const double a = 2 * kPi * i / kRim;
    const Eigen::Vector3d p =
        centre + options_.landmark_radius_m * Eigen::Vector3d(std::cos(a), std::sin(a), 0);
    const Eigen::Vector3d c = rt * (p - fit.translation);
    for (int side = 0; side < 2; ++side) {
      Eigen::Vector2d px;
      if (rig_->Project(side == 0 ? StereoSide::kLeft : StereoSide::kRight, c, &px)) {
        rim[side].push_back(px);
      }
    }
  }
  std::array<double, 2> area{0.0, 0.0};
  if (perimeter_px != nullptr) *perimeter_px = {0.0, 0.0};
  for (int side = 0; side < 2; ++side) {
    if (rim[side].size() != kRim) continue;  // partly behind the camera.
    for (int i = 0; i < kRim; ++i) {         // shoelace.
      const Eigen::Vector2d& a = rim[side][i];
      const Eigen::Vector2d& b = rim[side][(i + 1) % kRim];
      area[side] += a.x() * b.y() - b.x() * a.y();
      if (perimeter_px != nullptr) (*perimeter_px)[side] += (b - a).norm();
    }
    area[side] = std::abs(area[side]) / 2;
  }
  return area;
}

StereoEstimator::LandmarkVisibility StereoEstimator::AssessLandmark(
    const LandmarkMatch& match, int k, const std::vector<ColorBlob>& left_landmarks,
    const std::vector<ColorBlob>& right_landmarks, const std::vector<ColorBlob>& left_objects,
    const std::vector<ColorBlob>& right_objects, int width, int height) const {
  LandmarkVisibility v;
  const std::array<double, 2> predicted = PredictedDiscAreaPx(match.svd, k);
  std::vector<std::string> why;
  for (int side = 0; side < 2; ++side) {
    const std::vector<ColorBlob>& marks = side == 0 ? left_landmarks : right_landmarks;
    const std::vector<ColorBlob>& objects = side == 0 ? left_objects : right_objects;
    const int index = side == 0 ? match.left_index[k] : match.right_index[k];
    const ColorBlob& blob = marks[index];
    const char* name = side == 0 ? "left" : "right";
    {
      const double area = predicted[side];
      if (area > 1) {
        const double fraction = blob.area_px / area;
        v.visible_fraction = std::min(v.visible_fraction, fraction);
        if (fraction < options_.occlusion_area_ratio) {
          std::ostringstream s;
          s.precision(2);
          s << "covers " << fraction * 100 << " % of its predicted area in the " << name
            << " image";
          why.push_back(s.str());
        }
      }
    }
    auto touches = [&](const ColorBlob& b) {
      return blob.min_x <= b.max_x + 2 && b.min_x <= blob.max_x + 2 && blob.min_y <= b.max_y + 2 &&
             b.min_y <= blob.max_y + 2;
    };
    bool touched = false;
    for (const ColorBlob& o : objects) touched |= touches(o);
    for (size_t i = 0; i < marks.size(); ++i) {
      if (static_cast<int>(i) != index) touched |= touches(marks[i]);
    }
    if (touched) why.push_back(std::string("touches another blob in the ") + name + " image");
    if (blob.min_x == 0 || blob.min_y == 0 || blob.max_x == width - 1 || blob.max_y == height - 1) {
      why.push_back(std::string("is cut by the ") + name + " image's border");
    }
  }
  for (size_t i = 0; i < why.size(); ++i) v.note += (i > 0 ? ", " : "") + why[i];
  return v;
}

std::vector<StereoEstimator::ObjectCandidate> StereoEstimator::LocateObject(
    const std::vector<ColorBlob>& left, const std::vector<ColorBlob>& right,
    StereoFrameResult* result) const {
  std::vector<ObjectCandidate> found;
  if (left.empty() || right.empty()) {
    result->object_reason = std::string("no object-coloured blob in the ") +
                            (left.empty() ? "left" : "right") + " image";
    return found;
  }
  std::vector<Eigen::Vector2d> lpx, rpx;
  for (const ColorBlob& b : left) lpx.push_back(b.centroid_px);
  for (const ColorBlob& b : right) rpx.push_back(b.centroid_px);
  const std::vector<Eigen::Vector2d> ln = rig_->Normalize(StereoSide::kLeft, lpx);
  const std::vector<Eigen::Vector2d> rn = rig_->Normalize(StereoSide::kRight, rpx);
  const double fx = rig_->calibration().left.camera_matrix(0, 0);
  const double fy = rig_->calibration().left.camera_matrix(1, 1);
  std::string last_failure = "the object's blobs do not match across the pair";
  for (size_t i = 0; i < left.size(); ++i) {
    for (size_t j = 0; j < right.size(); ++j) {
      const ColorBlob& l = left[i];
      const ColorBlob& r = right[j];
      const double ratio = static_cast<double>(std::max(l.area_px, r.area_px)) /
                           std::max(1, std::min(l.area_px, r.area_px));
      if (ratio > options_.max_object_area_ratio) continue;
      const double err = rig_->EpipolarErrorPx(ln[i], rn[j]);
      if (err > options_.max_epipolar_error_px) continue;
      bool depth_ok = false;
      const Eigen::Vector3d p = rig_->Triangulate(ln[i], rn[j], &depth_ok);
      if (!depth_ok) continue;
      // A sphere of the ball's radius at this distance: a disc of about f R / d pixels.
      const double d = std::max(p.norm(), options_.ball_radius_m * 1.01);
      const double rad =
          options_.ball_radius_m / std::sqrt(d * d - std::pow(options_.ball_radius_m, 2));
      const double predicted = kPi * rad * rad * fx * fy;
      const double area = 0.5 * (l.area_px + r.area_px);
      const double size_error = std::abs(std::log(area / predicted));
      if (size_error > std::log(options_.max_ball_area_factor)) {
        std::ostringstream why;
        why.precision(3);
        why << "no ball-sized blob pair (closest: " << area << " px where a ball at " << d
            << " m covers " << predicted << " px)";
        last_failure = why.str();
        continue;
      }
      double fill_deficit = 0;
      for (const ColorBlob* b : {&l, &r}) {
        const int w = b->max_x - b->min_x + 1, h = b->max_y - b->min_y + 1;
        const double fill = static_cast<double>(b->area_px) / (w * h);
        // A round image never fills its bounding box (a disc fills pi/4).
        if (b->area_px >= 9 && fill > 0.95) fill_deficit = 1e9;
        if (b->area_px < 30) continue;  // too small to judge its shape further.
        // In angle, not pixels: pixels need not be square.
        const double aw = w / fx, ah = h / fy;
        const double aspect = std::max(aw, ah) / std::min(aw, ah);
        if (fill < options_.min_ball_fill || aspect > options_.max_ball_aspect) fill_deficit = 1e9;
        fill_deficit = std::max(fill_deficit, std::abs(fill - kPi / 4));
      }
      if (fill_deficit >= 1e9) {
        last_failure =
            "no round blob pair of the object's colour (the ball-sized ones are not round)";
        continue;
      }
      ObjectCandidate c;
      c.score = size_error + err / options_.max_epipolar_error_px + 2.0 * fill_deficit;
      c.sigma_m = std::sqrt(
          rig_->TriangulationCovariance(ln[i], rn[j], options_.centroid_sigma_px).trace());
      c.camera_m = p;
      c.left_px = l.centroid_px;
      c.right_px = r.centroid_px;
      c.epipolar_px = err;
      found.push_back(c);
    }
  }
  std::sort(found.begin(), found.end(),
            [](const ObjectCandidate& a, const ObjectCandidate& b) { return a.score < b.score; });
  if (found.empty()) {
    result->object_reason = last_failure;
  } else {
    SetObject(found.front(), result);
  }
  return found;
}

void StereoEstimator::SetObject(const ObjectCandidate& c, StereoFrameResult* result) {
  result->object_in_camera = true;
  result->object_camera_m = c.camera_m;
  result->object_left_px = c.left_px;
  result->object_right_px = c.right_px;
  result->object_epipolar_error_px = c.epipolar_px;
}

}  // namespace hpose
