#include "core/stereo/stereo_estimator.h"

#include <algorithm>
#include <cmath>
#include <sstream>

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

const char* StereoFrameStatusName(StereoFrameStatus status) {
  switch (status) {
    case StereoFrameStatus::kOk:
      return "ok";
    case StereoFrameStatus::kMissingLandmark:
      return "missing_landmark";
    case StereoFrameStatus::kTooManyLandmarks:
      return "too_many_landmarks";
    case StereoFrameStatus::kNoConsistentMatch:
      return "no_consistent_match";
    case StereoFrameStatus::kAmbiguousMatch:
      return "ambiguous_match";
    case StereoFrameStatus::kCollinearLandmarks:
      return "collinear_landmarks";
    case StereoFrameStatus::kPoorFit:
      return "poor_fit";
  }
  return "unknown";
}

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
                                                   double timestamp_s) const {
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
  LocateObject(lb[kObjectClass], rb[kObjectClass], &result);

  const std::vector<ColorBlob>& ll = lb[kLandmarkClass];
  const std::vector<ColorBlob>& rl = rb[kLandmarkClass];
  result.landmark_blobs_left = static_cast<int>(ll.size());
  result.landmark_blobs_right = static_cast<int>(rl.size());
  if (ll.size() != 3 || rl.size() != 3) {
    const bool left_bad = ll.size() != 3;
    const size_t n = left_bad ? ll.size() : rl.size();
    result.status =
        n < 3 ? StereoFrameStatus::kMissingLandmark : StereoFrameStatus::kTooManyLandmarks;
    result.reason = std::string(left_bad ? "left" : "right") + " image shows " + std::to_string(n) +
                    " landmark blob(s), need exactly 3";
    return result;
  }
  // A landmark partly hidden behind the object has a biased centroid.
  auto touches = [](const ColorBlob& a, const ColorBlob& b) {
    return a.min_x <= b.max_x + 2 && b.min_x <= a.max_x + 2 && a.min_y <= b.max_y + 2 &&
           b.min_y <= a.max_y + 2;
  };
  for (int side = 0; side < 2; ++side) {
    const auto& marks = side == 0 ? ll : rl;
    const auto& objects = side == 0 ? lb[kObjectClass] : rb[kObjectClass];
    for (const ColorBlob& m : marks) {
      for (const ColorBlob& o : objects) {
        if (touches(m, o)) {
          result.status = StereoFrameStatus::kMissingLandmark;
          result.reason = std::string("a landmark is partly hidden by the object in the ") +
                          (side == 0 ? "left" : "right") + " image";
          return result;
        }
      }
    }
  }
  for (const auto* side : {&ll, &rl}) {
    for (const ColorBlob& b : *side) {
      if (b.min_x == 0 || b.min_y == 0 || b.max_x == left.width - 1 || b.max_y == left.height - 1) {
        result.status = StereoFrameStatus::kMissingLandmark;
        result.reason = std::string("a landmark is cut by the ") +
                        (side == &ll ? "left" : "right") + " image's border";
        return result;
      }
    }
  }
  std::vector<Eigen::Vector2d> lpx, rpx;
  for (int i = 0; i < 3; ++i) {
    lpx.push_back(ll[i].centroid_px);
    rpx.push_back(rl[i].centroid_px);
  }
  const std::vector<Eigen::Vector2d> ln = rig_->Normalize(StereoSide::kLeft, lpx);
  const std::vector<Eigen::Vector2d> rn = rig_->Normalize(StereoSide::kRight, rpx);
  const LandmarkMatch match = MatchLandmarks(*rig_, ln, rn, options_);
  result.status = match.status;
  result.reason = match.reason;
  if (match.status != StereoFrameStatus::kOk &&
      match.status != StereoFrameStatus::kAmbiguousMatch &&
      match.status != StereoFrameStatus::kPoorFit) {
    return result;
  }
  if (match.hypotheses_tested == 0 || !std::isfinite(match.svd.rms_residual_m)) return result;
  for (int k = 0; k < 3; ++k) {
    result.landmark_left_px[k] = lpx[match.left_index[k]];
    result.landmark_right_px[k] = rpx[match.right_index[k]];
    result.landmark_camera_m[k] = match.camera_m[k];
  }
  result.max_epipolar_error_px = match.max_epipolar_error_px;
  result.svd = match.svd;
  Result<RigidFit> closed =
      FitRigidClosedForm(match.camera_m, options_.landmarks_world_m, options_.min_triangle_sine);
  result.closed_form_ok = closed.ok();
  if (closed.ok()) result.closed_form = *closed;
  if (match.status != StereoFrameStatus::kOk) return result;

  if (options_.method == RigidFitMethod::kClosedForm && !closed.ok()) {
    result.status = StereoFrameStatus::kCollinearLandmarks;
    result.reason = closed.error().message;
    return result;
  }
  const RigidFit& fit =
      options_.method == RigidFitMethod::kClosedForm ? result.closed_form : result.svd;
  const Eigen::Vector3d head = fit.rotation * (0.5 * rig_->RightCentreInLeft()) + fit.translation;
  const Eigen::Vector3d axis = fit.rotation.col(2);  // optical axis in the world frame.
  if (std::hypot(axis.x(), axis.y()) < 1e-3) {
    result.status = StereoFrameStatus::kPoorFit;
    result.reason = "the optical axis is vertical; the heading is undefined";
    return result;
  }
  result.robot.x = head.x();
  result.robot.y = head.y();
  result.robot.theta = NormalizeAngle(std::atan2(axis.y(), axis.x()));
  result.camera_height_m = head.z();
  if (result.object_in_camera) {
    result.object_world_m = fit.rotation * result.object_camera_m + fit.translation;
    result.object_in_world = true;
  } else if (result.object_reason.empty()) {
    result.object_reason = "object not seen";
  }
  return result;
}

void StereoEstimator::LocateObject(const std::vector<ColorBlob>& left,
                                   const std::vector<ColorBlob>& right,
                                   StereoFrameResult* result) const {
  if (left.empty() || right.empty()) {
    result->object_reason = std::string("no object-coloured blob in the ") +
                            (left.empty() ? "left" : "right") + " image";
    return;
  }
  const ColorBlob& l = left.front();  // the largest.
  const Eigen::Vector2d ln = rig_->Normalize(StereoSide::kLeft, {l.centroid_px}).front();
  std::vector<Eigen::Vector2d> rpx;
  for (const ColorBlob& b : right) rpx.push_back(b.centroid_px);
  const std::vector<Eigen::Vector2d> rn = rig_->Normalize(StereoSide::kRight, rpx);
  double best_err = options_.max_epipolar_error_px;
  int best = -1;
  for (size_t i = 0; i < right.size(); ++i) {
    const double ratio = static_cast<double>(std::max(l.area_px, right[i].area_px)) /
                         std::max(1, std::min(l.area_px, right[i].area_px));
    if (ratio > options_.max_object_area_ratio) continue;
    const double err = rig_->EpipolarErrorPx(ln, rn[i]);
    if (err > best_err) continue;
    bool depth_ok = false;
    rig_->Triangulate(ln, rn[i], &depth_ok);
    if (!depth_ok) continue;
    best_err = err;
    best = static_cast<int>(i);
  }
  if (best < 0) {
    result->object_reason = "the object's blobs do not match across the pair";
    return;
  }
  bool depth_ok = false;
  result->object_camera_m = rig_->Triangulate(ln, rn[best], &depth_ok);
  result->object_left_px = l.centroid_px;
  result->object_right_px = right[best].centroid_px;
  result->object_epipolar_error_px = best_err;
  result->object_in_camera = depth_ok;
}

}  // namespace hpose
