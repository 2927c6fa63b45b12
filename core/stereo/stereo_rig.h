#ifndef HPOSE_CORE_STEREO_STEREO_RIG_H_
#define HPOSE_CORE_STEREO_STEREO_RIG_H_

#include <memory>
#include <vector>

#include <Eigen/Core>

#include "core/common/status.h"
#include "core/stereo/stereo_calibration.h"

namespace hpose {

enum class StereoSide { kLeft, kRight };

// The geometry of a calibrated stereo pair: lens-distortion correction of individual image
// points, epipolar distances and triangulation. Points are corrected one by one (never whole
// images). All 3D output is in the left camera frame (x right, y down, z forward, metres).
class StereoRig final {
 public:
  // Fails with kInvalidArgument when the calibration does not validate.
  static Result<std::unique_ptr<StereoRig>> Create(const StereoCalibration& calibration);
  ~StereoRig();
  StereoRig(const StereoRig&) = delete;
  StereoRig& operator=(const StereoRig&) = delete;

  // Distorted pixel coordinates -> undistorted normalised image coordinates (x/z, y/z) of one
  // camera, by OpenCV's iterative inversion of the distortion model.
  std::vector<Eigen::Vector2d> Normalize(StereoSide side,
                                         const std::vector<Eigen::Vector2d>& pixels) const;

  // Distance of the pair (left, right) of normalised points from each other's epipolar lines,
  // averaged over both images and expressed in pixels of the respective camera.
  double EpipolarErrorPx(const Eigen::Vector2d& left_normalized,
                         const Eigen::Vector2d& right_normalized) const;

  // Linear (DLT) triangulation by OpenCV of one correspondence of normalised points, in the
  // left camera frame. `depth_ok` is set to whether the point lies in front of both cameras.
  Eigen::Vector3d Triangulate(const Eigen::Vector2d& left_normalized,
                              const Eigen::Vector2d& right_normalized, bool* depth_ok) const;

  // Covariance (m^2, left camera frame) of Triangulate's point when each image coordinate of
  // both points carries independent noise of `sigma_px` pixels (first-order propagation).
  Eigen::Matrix3d TriangulationCovariance(const Eigen::Vector2d& left_normalized,
                                          const Eigen::Vector2d& right_normalized,
                                          double sigma_px) const;

  // The right camera's optical centre in the left camera frame, metres.
  Eigen::Vector3d RightCentreInLeft() const;

  // Projection of a point in the left camera frame into one camera's distorted pixels (for
  // tests and the simulator). Returns false when the point is behind that camera.
  bool Project(StereoSide side, const Eigen::Vector3d& point_left, Eigen::Vector2d* pixel) const;

  const StereoCalibration& calibration() const { return calibration_; }

 private:
  struct CvState;
  explicit StereoRig(const StereoCalibration& calibration);

  StereoCalibration calibration_;
  Eigen::Matrix3d essential_;  // right_normalized^T * E * left_normalized = 0.
  std::unique_ptr<CvState> cv_;
};

}  // namespace hpose

#endif  // HPOSE_CORE_STEREO_STEREO_RIG_H_
