#include "core/stereo/stereo_rig.h"

#include <cmath>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

namespace hpose {

struct StereoRig::CvState {
  cv::Mat k[2];
  cv::Mat d[2];
  cv::Mat r_right;  // Rodrigues vector of right_R_left.
  cv::Mat t_right;
  cv::Mat proj_left;   // [I | 0]
  cv::Mat proj_right;  // [R | T]
};

namespace {

cv::Mat ToCv(const Eigen::MatrixXd& m) {
  cv::Mat out(static_cast<int>(m.rows()), static_cast<int>(m.cols()), CV_64F);
  for (int r = 0; r < m.rows(); ++r)
    for (int c = 0; c < m.cols(); ++c) out.at<double>(r, c) = m(r, c);
  return out;
}

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d s;
  s << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return s;
}

}  // namespace

Result<std::unique_ptr<StereoRig>> StereoRig::Create(const StereoCalibration& calibration) {
  Status valid = ValidateStereoCalibration(calibration, "stereo calibration");
  if (!valid.ok()) return valid.error();
  return std::unique_ptr<StereoRig>(new StereoRig(calibration));
}

StereoRig::StereoRig(const StereoCalibration& calibration)
    : calibration_(calibration), cv_(std::make_unique<CvState>()) {
  const CameraModel* cams[2] = {&calibration_.left, &calibration_.right};
  for (int i = 0; i < 2; ++i) {
    cv_->k[i] = ToCv(cams[i]->camera_matrix);
    cv_->d[i] =
        cams[i]->distortion.empty() ? cv::Mat() : cv::Mat(cams[i]->distortion, true).reshape(1, 1);
  }
  cv::Rodrigues(ToCv(calibration_.right_R_left), cv_->r_right);
  cv_->t_right = ToCv(calibration_.right_t_left);
  Eigen::Matrix<double, 3, 4> pl = Eigen::Matrix<double, 3, 4>::Zero();
  pl.leftCols<3>().setIdentity();
  Eigen::Matrix<double, 3, 4> pr;
  pr << calibration_.right_R_left, calibration_.right_t_left;
  cv_->proj_left = ToCv(pl);
  cv_->proj_right = ToCv(pr);
  essential_ = Skew(calibration_.right_t_left) * calibration_.right_R_left;
}

StereoRig::~StereoRig() = default;

std::vector<Eigen::Vector2d> StereoRig::Normalize(
    StereoSide side, const std::vector<Eigen::Vector2d>& pixels) const {
  std::vector<Eigen::Vector2d> out;
  if (pixels.empty()) return out;
  const int i = side == StereoSide::kLeft ? 0 : 1;
  std::vector<cv::Point2d> src, dst;
  src.reserve(pixels.size());
  for (const Eigen::Vector2d& p : pixels) src.emplace_back(p.x(), p.y());
  cv::undistortPoints(src, dst, cv_->k[i], cv_->d[i], cv::noArray(), cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 20, 1e-12));
  out.reserve(dst.size());
  for (const cv::Point2d& p : dst) out.emplace_back(p.x, p.y);
  return out;
}

double StereoRig::EpipolarErrorPx(const Eigen::Vector2d& left_normalized,
                                  const Eigen::Vector2d& right_normalized) const {
  const Eigen::Vector3d xl(left_normalized.x(), left_normalized.y(), 1.0);
  const Eigen::Vector3d xr(right_normalized.x(), right_normalized.y(), 1.0);
  const Eigen::Vector3d line_r = essential_ * xl;              // in the right image.
  const Eigen::Vector3d line_l = essential_.transpose() * xr;  // in the left image.
  const double algebraic = std::abs(xr.dot(line_r));
  const double dr = algebraic / std::max(1e-12, line_r.head<2>().norm());
  const double dl = algebraic / std::max(1e-12, line_l.head<2>().norm());
  const double fr = calibration_.right.camera_matrix(1, 1);
  const double fl = calibration_.left.camera_matrix(1, 1);
  return 0.5 * (dr * fr + dl * fl);
}

Eigen::Vector3d StereoRig::Triangulate(const Eigen::Vector2d& left_normalized,
                                       const Eigen::Vector2d& right_normalized,
                                       bool* depth_ok) const {
  cv::Mat pl = (cv::Mat_<double>(2, 1) << left_normalized.x(), left_normalized.y());
  cv::Mat pr = (cv::Mat_<double>(2, 1) << right_normalized.x(), right_normalized.y());
  cv::Mat homog;
  cv::triangulatePoints(cv_->proj_left, cv_->proj_right, pl, pr, homog);
  const double w = homog.at<double>(3, 0);
  Eigen::Vector3d x(homog.at<double>(0, 0), homog.at<double>(1, 0), homog.at<double>(2, 0));
  if (std::abs(w) < 1e-15) {
    if (depth_ok != nullptr) *depth_ok = false;
    return Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  }
  x /= w;
  if (depth_ok != nullptr) {
    const Eigen::Vector3d xr = calibration_.right_R_left * x + calibration_.right_t_left;
    *depth_ok = x.z() > 0 && xr.z() > 0 && x.allFinite();
  }
  return x;
}

Eigen::Vector3d StereoRig::RightCentreInLeft() const {
  return -calibration_.right_R_left.transpose() * calibration_.right_t_left;
}

bool StereoRig::Project(StereoSide side, const Eigen::Vector3d& point_left,
                        Eigen::Vector2d* pixel) const {
  const int i = side == StereoSide::kLeft ? 0 : 1;
  const Eigen::Vector3d p =
      i == 0 ? point_left
             : Eigen::Vector3d(calibration_.right_R_left * point_left + calibration_.right_t_left);
  if (p.z() <= 0) return false;
  std::vector<cv::Point3d> obj = {cv::Point3d(p.x(), p.y(), p.z())};
  std::vector<cv::Point2d> img;
  cv::projectPoints(obj, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), cv_->k[i], cv_->d[i], img);
  *pixel = Eigen::Vector2d(img[0].x, img[0].y);
  return true;
}

Eigen::Matrix3d StereoRig::TriangulationCovariance(const Eigen::Vector2d& left_normalized,
                                                   const Eigen::Vector2d& right_normalized,
                                                   double sigma_px) const {
  bool ok = false;
  // Jacobian with respect to the four image coordinates, by central differences of one pixel.
  Eigen::Matrix<double, 3, 4> j;
  const double f[4] = {calibration_.left.camera_matrix(0, 0), calibration_.left.camera_matrix(1, 1),
                       calibration_.right.camera_matrix(0, 0),
                       calibration_.right.camera_matrix(1, 1)};
  for (int k = 0; k < 4; ++k) {
    Eigen::Vector2d l = left_normalized, r = right_normalized;
    const double h = 0.5 / f[k];
    Eigen::Vector2d& v = k < 2 ? l : r;
    v[k % 2] += h;
    const Eigen::Vector3d plus = Triangulate(l, r, &ok);
    v[k % 2] -= 2 * h;
    const Eigen::Vector3d minus = Triangulate(l, r, &ok);
    j.col(k) = (plus - minus);  // per pixel (step of one pixel in total).
  }
  return sigma_px * sigma_px * j * j.transpose();
}

}  // namespace hpose
