#ifndef HPOSE_CORE_STEREO_STEREO_CALIBRATOR_H_
#define HPOSE_CORE_STEREO_STEREO_CALIBRATOR_H_

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/common/status.h"
#include "core/stereo/rgb_image.h"
#include "core/stereo/stereo_calibration.h"

namespace hpose {

// The chessboard seen by both cameras.
struct ChessboardOptions {
  int inner_columns = 9;    // inner corners along a row.
  int inner_rows = 6;       // inner corners along a column.
  double square_m = 0.025;  // side of one square, metres (sets the unit of the baseline).
};

// One left/right image pair given to the calibration.
struct StereoCalibrationView {
  std::string name;  // for the report (e.g. the file names).
  RgbImage left;
  RgbImage right;
};

// What the calibration found, per view and overall.
struct StereoCalibrationReport {
  StereoCalibration calibration;
  double rms_px = 0.0;       // RMS reprojection error of the joint stereo fit (OpenCV's), pixels.
  double left_rms_px = 0.0;  // of each camera's own intrinsic calibration.
  double right_rms_px = 0.0;
  struct View {
    std::string name;
    bool used = false;         // the board was found in both images.
    std::string reason;        // why not, when not used.
    double left_rms_px = 0.0;  // per-view RMS of the stereo fit (left, right image), pixels.
    double right_rms_px = 0.0;
    // The board's inner corners found (row by row, distorted pixels), when used.
    std::vector<Eigen::Vector2d> left_corners;
    std::vector<Eigen::Vector2d> right_corners;
  };
  std::vector<View> views;
  // Rectification (cv::stereoRectify, alpha 0): rotations of each camera into the rectified
  // frame, the rectified projection matrices (pixels) and the disparity-to-depth matrix.
  Eigen::Matrix3d rect_left = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d rect_right = Eigen::Matrix3d::Identity();
  Eigen::Matrix<double, 3, 4> proj_left = Eigen::Matrix<double, 3, 4>::Zero();
  Eigen::Matrix<double, 3, 4> proj_right = Eigen::Matrix<double, 3, 4>::Zero();
  Eigen::Matrix4d disparity_to_depth = Eigen::Matrix4d::Zero();
};

// Calibrates a stereo pair from chessboard views with OpenCV: findChessboardCorners and
// cornerSubPix in every image, calibrateCamera for each camera's intrinsics (k1 k2 p1 p2 k3),
// then stereoCalibrate for the relative pose (intrinsics refined jointly) with per-view errors,
// and stereoRectify. The translation comes out in metres (square_m). `progress` (optional) is
// called after each view's corner search. Fails with kInvalidArgument when the views differ in
// size or the options are bad (3 to 100 inner corners a side, squares of (0, 1] m) or OpenCV
// refuses the data, and kFailedPrecondition when fewer than 3 views show the whole board in both
// images (naming how many did).
Result<StereoCalibrationReport> CalibrateStereo(
    const std::vector<StereoCalibrationView>& views, const ChessboardOptions& board,
    const std::function<void(const StereoCalibrationReport::View&)>& progress = nullptr);

// Writes the calibration (as WriteStereoCalibration) plus the rectification (R1 R2 P1 P2 Q)
// and the RMS error, so that the estimator reads it directly. Fails with kInternal.
Status WriteStereoCalibrationReport(const StereoCalibrationReport& report, const std::string& path);

}  // namespace hpose

#endif  // HPOSE_CORE_STEREO_STEREO_CALIBRATOR_H_
