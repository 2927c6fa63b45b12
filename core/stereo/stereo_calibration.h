#ifndef HPOSE_CORE_STEREO_STEREO_CALIBRATION_H_
#define HPOSE_CORE_STEREO_STEREO_CALIBRATION_H_

#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/common/status.h"

namespace hpose {

// One pinhole camera with OpenCV's distortion model (k1 k2 p1 p2 [k3 [k4 k5 k6]]).
struct CameraModel {
  Eigen::Matrix3d camera_matrix = Eigen::Matrix3d::Identity();  // fx 0 cx; 0 fy cy; 0 0 1 (px).
  std::vector<double> distortion;  // 0, 4, 5, 8, 12 or 14 coefficients; empty = none.
};

// A calibrated stereo pair in OpenCV's convention: a point X_left in the left camera frame
// (x right, y down, z forward, metres) is X_right = R * X_left + T in the right camera frame,
// i.e. R, T are right_from_left.
struct StereoCalibration {
  CameraModel left;
  CameraModel right;
  Eigen::Matrix3d right_R_left = Eigen::Matrix3d::Identity();
  Eigen::Vector3d right_t_left = Eigen::Vector3d::Zero();  // metres.
  int image_width = 0;   // pixels; 0 = not stated in the file (then not checked).
  int image_height = 0;  // pixels; 0 = not stated in the file.

  // Distance between the optical centres, metres.
  double BaselineM() const { return right_t_left.norm(); }
};

struct StereoCalibrationReadOptions {
  // Metres per unit of T in the file. OpenCV's T is in the unit of the calibration target's
  // square size: 1.0 when that was metres, 0.001 when millimetres. A file's own
  // "translation_unit" entry ("m" or "mm") overrides this.
  double translation_unit_m = 1.0;
  // Plausible baseline range after scaling, metres; outside it the file is rejected (usually a
  // unit mix-up).
  double min_baseline_m = 0.005;
  double max_baseline_m = 2.0;
};

// Reads an OpenCV stereo calibration written with cv::FileStorage (YAML, XML or JSON, as the
// stereo_calib sample and most calibration tools produce). `paths` may hold one file with
// everything or two (intrinsics + extrinsics) that are merged. Accepted names:
//   left camera matrix  M1 | K1 | cameraMatrix1 | camera_matrix_left | cameraMatrixL
//   left distortion     D1 | distCoeffs1 | dist_coeffs_left | distCoeffsL
//   right camera matrix M2 | K2 | cameraMatrix2 | camera_matrix_right | cameraMatrixR
//   right distortion    D2 | distCoeffs2 | dist_coeffs_right | distCoeffsR
//   rotation            R;  translation T;  optional image_width, image_height (or
//   imageSize / image_size as [w, h]) and translation_unit ("m" | "mm").
// Fails with kNotFound (missing file), kDataLoss (not a FileStorage file) or kInvalidArgument
// (missing entry, wrong matrix size, non-finite value, R not a rotation, implausible baseline),
// naming the file and the entry.
Result<StereoCalibration> ReadStereoCalibration(const std::vector<std::string>& paths,
                                                const StereoCalibrationReadOptions& options = {});

// Checks a calibration for the problems listed above. `where` prefixes the messages.
Status ValidateStereoCalibration(const StereoCalibration& calibration, const std::string& where,
                                 const StereoCalibrationReadOptions& options = {});

// A further matrix to store beside the calibration (e.g. rectification, errors).
struct NamedMatrix {
  std::string name;
  Eigen::MatrixXd value;
};

// Writes the calibration as OpenCV FileStorage (".yaml"/".yml" or ".xml" chosen by extension)
// with the names M1 D1 M2 D2 R T image_width image_height and translation_unit "m", then the
// `extra` matrices (which readers ignore). Fails with kInternal when the file cannot be written.
Status WriteStereoCalibration(const StereoCalibration& calibration, const std::string& path,
                              const std::vector<NamedMatrix>& extra = {});

}  // namespace hpose

#endif  // HPOSE_CORE_STEREO_STEREO_CALIBRATION_H_
