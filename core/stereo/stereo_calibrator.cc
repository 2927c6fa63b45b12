#include "core/stereo/stereo_calibrator.h"

#include <cmath>
#include <sstream>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace hpose {
namespace {

cv::Mat Gray(const RgbImage& image) {
  const cv::Mat rgb(image.height, image.width, CV_8UC3,
                    const_cast<std::uint8_t*>(image.pixels.data()));
  cv::Mat gray;
  cv::cvtColor(rgb, gray, cv::COLOR_RGB2GRAY);
  return gray;
}

bool FindCorners(const RgbImage& image, const cv::Size& pattern,
                 std::vector<cv::Point2f>* corners) {
  const cv::Mat gray = Gray(image);
  const bool found = cv::findChessboardCorners(
      gray, pattern, *corners, cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE);
  if (!found) return false;
  cv::cornerSubPix(gray, *corners, cv::Size(11, 11), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01));
  return true;
}

template <typename Derived>
Eigen::MatrixXd ToEigen(const cv::Mat& m, Derived* out) {
  Eigen::MatrixXd e(m.rows, m.cols);
  for (int r = 0; r < m.rows; ++r)
    for (int c = 0; c < m.cols; ++c) e(r, c) = m.at<double>(r, c);
  if (out != nullptr) *out = e;
  return e;
}

std::vector<double> ToVector(const cv::Mat& m) {
  std::vector<double> v;
  for (int i = 0; i < static_cast<int>(m.total()); ++i) v.push_back(m.at<double>(i));
  return v;
}

Result<StereoCalibrationReport> CalibrateStereoUnguarded(
    const std::vector<StereoCalibrationView>& views, const ChessboardOptions& board,
    const std::function<void(const StereoCalibrationReport::View&)>& progress) {
  if (views.empty()) return MakeError(ErrorCode::kInvalidArgument, "no image pairs given");
  const int width = views.front().left.width, height = views.front().left.height;
  for (const StereoCalibrationView& v : views) {
    if (!v.left.valid() || !v.right.valid() || v.left.width != width || v.left.height != height ||
        v.right.width != width || v.right.height != height) {
      return MakeError(ErrorCode::kInvalidArgument,
                       v.name + ": images must be valid and all of the size of the first (" +
                           std::to_string(width) + "x" + std::to_string(height) + ")");
    }
  }
  const cv::Size pattern(board.inner_columns, board.inner_rows);
  std::vector<cv::Point3f> object;
  for (int r = 0; r < board.inner_rows; ++r)
    for (int c = 0; c < board.inner_columns; ++c)
      object.emplace_back(static_cast<float>(c * board.square_m),
                          static_cast<float>(r * board.square_m), 0.f);

  StereoCalibrationReport report;
  std::vector<std::vector<cv::Point3f>> objects;
  std::vector<std::vector<cv::Point2f>> left_points, right_points;
  std::vector<size_t> used_views;
  for (size_t i = 0; i < views.size(); ++i) {
    StereoCalibrationReport::View v;
    v.name = views[i].name;
    std::vector<cv::Point2f> l, r;
    const bool left_found = FindCorners(views[i].left, pattern, &l);
    const bool right_found = left_found && FindCorners(views[i].right, pattern, &r);
    if (!left_found || !right_found) {
      v.reason = std::string("the ") + std::to_string(board.inner_columns) + "x" +
                 std::to_string(board.inner_rows) + " board was not found in the " +
                 (left_found ? "right" : "left") + " image";
    } else {
      v.used = true;
      for (const cv::Point2f& p : l) v.left_corners.emplace_back(p.x, p.y);
      for (const cv::Point2f& p : r) v.right_corners.emplace_back(p.x, p.y);
      objects.push_back(object);
      left_points.push_back(l);
      right_points.push_back(r);
      used_views.push_back(report.views.size());
    }
    report.views.push_back(v);
    if (progress) progress(v);
  }
  if (objects.size() < 3) {
    return MakeError(ErrorCode::kFailedPrecondition,
                     "the chessboard was found in both images of only " +
                         std::to_string(objects.size()) + " of " + std::to_string(views.size()) +
                         " pairs; at least 3 are needed");
  }
  const cv::Size size(width, height);
  cv::Mat k1, d1, k2, d2, rv, tv;
  report.left_rms_px = cv::calibrateCamera(objects, left_points, size, k1, d1, rv, tv);
  report.right_rms_px = cv::calibrateCamera(objects, right_points, size, k2, d2, rv, tv);
  cv::Mat r, t, e, f, per_view;
  report.rms_px = cv::stereoCalibrate(
      objects, left_points, right_points, k1, d1, k2, d2, size, r, t, e, f, per_view,
      cv::CALIB_USE_INTRINSIC_GUESS,
      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-6));
  for (size_t i = 0; i < used_views.size(); ++i) {
    report.views[used_views[i]].left_rms_px = per_view.at<double>(static_cast<int>(i), 0);
    report.views[used_views[i]].right_rms_px = per_view.at<double>(static_cast<int>(i), 1);
  }
  StereoCalibration& cal = report.calibration;
  ToEigen(k1, &cal.left.camera_matrix);
  ToEigen(k2, &cal.right.camera_matrix);
  cal.left.distortion = ToVector(d1);
  cal.right.distortion = ToVector(d2);
  ToEigen(r, &cal.right_R_left);
  ToEigen(t, &cal.right_t_left);
  cal.image_width = width;
  cal.image_height = height;

  cv::Mat r1, r2, p1, p2, q;
  cv::stereoRectify(k1, d1, k2, d2, size, r, t, r1, r2, p1, p2, q, cv::CALIB_ZERO_DISPARITY, 0);
  ToEigen(r1, &report.rect_left);
  ToEigen(r2, &report.rect_right);
  ToEigen(p1, &report.proj_left);
  ToEigen(p2, &report.proj_right);
  ToEigen(q, &report.disparity_to_depth);
  Status valid = ValidateStereoCalibration(cal, "stereo calibration result");
  if (!valid.ok()) return valid.error();
  return report;
}

}  // namespace

Result<StereoCalibrationReport> CalibrateStereo(
    const std::vector<StereoCalibrationView>& views, const ChessboardOptions& board,
    const std::function<void(const StereoCalibrationReport::View&)>& progress) {
  // OpenCV's corner search needs more than 2 corners a side (it throws otherwise).
  if (board.inner_columns < 3 || board.inner_rows < 3 || board.inner_columns > 100 ||
      board.inner_rows > 100 || !(board.square_m > 0 && board.square_m <= 1.0)) {
    std::ostringstream msg;
    msg << "chessboard: needs 3 to 100 inner corners a side and a square of (0, 1] m, got "
        << board.inner_columns << "x" << board.inner_rows << " corners of " << board.square_m
        << " m";
    return MakeError(ErrorCode::kInvalidArgument, msg.str());
  }
  try {
    return CalibrateStereoUnguarded(views, board, progress);
  } catch (const cv::Exception& e) {  // an assertion of OpenCV's on data it cannot calibrate.
    return MakeError(ErrorCode::kInvalidArgument,
                     std::string("stereo calibration failed in OpenCV: ") + e.what());
  }
}

Status WriteStereoCalibrationReport(const StereoCalibrationReport& report,
                                    const std::string& path) {
  Eigen::MatrixXd rms(1, 1);
  rms(0, 0) = report.rms_px;
  return WriteStereoCalibration(report.calibration, path,
                                {{"R1", report.rect_left},
                                 {"R2", report.rect_right},
                                 {"P1", report.proj_left},
                                 {"P2", report.proj_right},
                                 {"Q", report.disparity_to_depth},
                                 {"rms_reprojection_error_px", rms}});
}

}  // namespace hpose
