#include "core/stereo/local_marker_estimator.h"

#include <cmath>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

namespace hpose {
namespace {

std::vector<Eigen::Vector2d> Normalize(const CameraModel& cam,
                                       const std::vector<Eigen::Vector2d>& px) {
  cv::Mat k(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) k.at<double>(r, c) = cam.camera_matrix(r, c);
  const cv::Mat d =
      cam.distortion.empty() ? cv::Mat() : cv::Mat(cam.distortion, true).reshape(1, 1);
  std::vector<cv::Point2d> src, dst;
  for (const Eigen::Vector2d& p : px) src.emplace_back(p.x(), p.y());
  cv::undistortPoints(src, dst, k, d, cv::noArray(), cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 20, 1e-12));
  std::vector<Eigen::Vector2d> out;
  for (const cv::Point2d& p : dst) out.emplace_back(p.x, p.y);
  return out;
}

}  // namespace

Result<std::unique_ptr<LocalMarkerEstimator>> LocalMarkerEstimator::Create(
    const CameraModel& camera, const LocalMarkerOptions& options) {
  const Eigen::Matrix3d& k = camera.camera_matrix;
  if (!k.allFinite() || !(k(0, 0) > 0) || !(k(1, 1) > 0)) {
    return MakeError(ErrorCode::kInvalidArgument, "local mode: invalid camera matrix");
  }
  if (!(options.marker_spacing_m > 0) || !std::isfinite(options.marker_spacing_m)) {
    return MakeError(ErrorCode::kInvalidArgument, "local mode: marker_spacing_m must be > 0");
  }
  if (!std::isfinite(options.object_height_above_markers_m)) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "local mode: object_height_above_markers_m is not finite");
  }
  auto seg =
      ColorSegmenter::Create({options.marker_color, options.object_color}, options.segmentation);
  if (!seg.ok()) return seg.error();
  return std::unique_ptr<LocalMarkerEstimator>(
      new LocalMarkerEstimator(camera, std::move(seg).value(), options));
}

LocalMarkerEstimator::LocalMarkerEstimator(const CameraModel& camera, ColorSegmenter segmenter,
                                           const LocalMarkerOptions& options)
    : camera_(camera), segmenter_(std::move(segmenter)), options_(options) {}

Result<LocalObjectResult> LocalMarkerEstimator::Process(const RgbImage& image) const {
  if (!image.valid()) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "local mode: image is empty or its buffer does not match its size");
  }
  const auto blobs = segmenter_.Segment(image);
  if (blobs[0].size() != 2) {
    return MakeError(ErrorCode::kFailedPrecondition,
                     "local mode: " + std::to_string(blobs[0].size()) +
                         " marker blob(s) in the image, need exactly 2");
  }
  if (blobs[1].empty()) {
    return MakeError(ErrorCode::kFailedPrecondition, "local mode: no object blob in the image");
  }
  // The right marker is the one further right in the image (image x grows to the robot's right).
  const bool first_is_right = blobs[0][0].centroid_px.x() > blobs[0][1].centroid_px.x();
  LocalObjectResult out;
  out.marker_px[0] = blobs[0][first_is_right ? 0 : 1].centroid_px;
  out.marker_px[1] = blobs[0][first_is_right ? 1 : 0].centroid_px;
  out.object_px = blobs[1][0].centroid_px;
  const std::vector<Eigen::Vector2d> n =
      Normalize(camera_, {out.marker_px[0], out.marker_px[1], out.object_px});
  const Eigen::Vector2d across = n[1] - n[0];  // right -> left marker, normalised units.
  if (across.norm() < 1e-9) {
    return MakeError(ErrorCode::kFailedPrecondition, "local mode: the two markers coincide");
  }
  out.marker_depth_m = options_.marker_spacing_m / across.norm();
  const Eigen::Vector2d y_axis = across.normalized();
  const Eigen::Vector2d x_axis(-y_axis.y(), y_axis.x());  // image "up" when the markers are level.
  const Eigen::Vector2d mid = 0.5 * (n[0] + n[1]) * out.marker_depth_m;
  const Eigen::Vector2d obj = n[2] * (out.marker_depth_m - options_.object_height_above_markers_m);
  const Eigen::Vector2d rel = obj - mid;
  out.object_in_robot_m = Eigen::Vector2d(rel.dot(x_axis), rel.dot(y_axis));
  return out;
}

}  // namespace hpose
