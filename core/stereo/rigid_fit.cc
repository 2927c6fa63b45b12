#include "core/stereo/rigid_fit.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>

namespace hpose {
namespace {

double SineAt(const Eigen::Vector3d& apex, const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
  const Eigen::Vector3d u = p - apex, v = q - apex;
  const double denom = u.norm() * v.norm();
  if (denom <= 0) return 0.0;
  return u.cross(v).norm() / denom;
}

template <typename Container>
void Residuals(const Container& src, const Container& dst, RigidFit* fit) {
  double sum = 0, worst = 0;
  for (size_t i = 0; i < src.size(); ++i) {
    const double r = (fit->rotation * src[i] + fit->translation - dst[i]).norm();
    sum += r * r;
    worst = std::max(worst, r);
  }
  fit->rms_residual_m = std::sqrt(sum / static_cast<double>(src.size()));
  fit->max_residual_m = worst;
  fit->orthonormality_error =
      (fit->rotation.transpose() * fit->rotation - Eigen::Matrix3d::Identity()).norm();
}

Eigen::Matrix3d Basis(const std::array<Eigen::Vector3d, 3>& p) {
  const Eigen::Vector3d e1 = p[1] - p[0], e2 = p[2] - p[0];
  const Eigen::Vector3d n = e2.cross(e1);
  Eigen::Matrix3d b;
  b.col(0) = e1.normalized();
  b.col(1) = e2.normalized();
  b.col(2) = n.normalized();
  return b;
}

}  // namespace

double TriangleMinSine(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                       const Eigen::Vector3d& c) {
  return std::min({SineAt(a, b, c), SineAt(b, c, a), SineAt(c, a, b)});
}

Result<RigidFit> FitRigidClosedForm(const std::array<Eigen::Vector3d, 3>& src,
                                    const std::array<Eigen::Vector3d, 3>& dst, double min_sine) {
  for (const auto* set : {&src, &dst}) {
    for (const Eigen::Vector3d& p : *set) {
      if (!p.allFinite()) {
        return MakeError(ErrorCode::kInvalidArgument, "rigid fit: non-finite point");
      }
    }
    if (TriangleMinSine((*set)[0], (*set)[1], (*set)[2]) < min_sine) {
      return MakeError(ErrorCode::kFailedPrecondition,
                       std::string("rigid fit: the three ") +
                           (set == &src ? "source" : "destination") +
                           " points are (nearly) collinear");
    }
  }
  RigidFit fit;
  const Eigen::Matrix3d bs = Basis(src), bd = Basis(dst);
  fit.rotation = bd * bs.inverse();
  fit.translation = dst[0] - fit.rotation * src[0];
  Residuals(src, dst, &fit);
  return fit;
}

Result<RigidFit> FitRigidSvd(const std::vector<Eigen::Vector3d>& src,
                             const std::vector<Eigen::Vector3d>& dst, double min_sine,
                             const std::vector<double>& weights) {
  if (src.size() < 3 || src.size() != dst.size()) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "rigid fit: needs at least 3 point pairs of equal count, got " +
                         std::to_string(src.size()) + " and " + std::to_string(dst.size()));
  }
  const int n = static_cast<int>(src.size());
  Eigen::Matrix3Xd s(3, n), d(3, n);
  for (int i = 0; i < n; ++i) {
    if (!src[i].allFinite() || !dst[i].allFinite()) {
      return MakeError(ErrorCode::kInvalidArgument, "rigid fit: non-finite point");
    }
    s.col(i) = src[i];
    d.col(i) = dst[i];
  }
  // Collinearity: the second singular value of the centred source points relative to the first.
  const Eigen::Matrix3Xd centred = s.colwise() - s.rowwise().mean();
  const Eigen::JacobiSVD<Eigen::Matrix3Xd> svd(centred);
  const Eigen::Vector3d sv = svd.singularValues();
  if (n == 3 ? TriangleMinSine(src[0], src[1], src[2]) < min_sine
             : (sv(0) <= 0 || sv(1) / sv(0) < min_sine)) {
    return MakeError(ErrorCode::kFailedPrecondition,
                     "rigid fit: the source points are (nearly) collinear");
  }
  RigidFit fit;
  if (weights.empty()) {
    const Eigen::Matrix4d t = Eigen::umeyama(s, d, false);
    fit.rotation = t.topLeftCorner<3, 3>();
    fit.translation = t.topRightCorner<3, 1>();
  } else {
    if (weights.size() != src.size()) {
      return MakeError(ErrorCode::kInvalidArgument, "rigid fit: one weight per point pair needed");
    }
    double sum = 0;
    Eigen::Vector3d ms = Eigen::Vector3d::Zero(), md = Eigen::Vector3d::Zero();
    for (int i = 0; i < n; ++i) {
      if (!(weights[i] > 0) || !std::isfinite(weights[i])) {
        return MakeError(ErrorCode::kInvalidArgument, "rigid fit: weights must be positive");
      }
      sum += weights[i];
      ms += weights[i] * s.col(i);
      md += weights[i] * d.col(i);
    }
    ms /= sum;
    md /= sum;
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (int i = 0; i < n; ++i) cov += weights[i] * (d.col(i) - md) * (s.col(i) - ms).transpose();
    const Eigen::JacobiSVD<Eigen::Matrix3d> k(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d fix = Eigen::Matrix3d::Identity();
    if ((k.matrixU() * k.matrixV().transpose()).determinant() < 0) fix(2, 2) = -1;
    fit.rotation = k.matrixU() * fix * k.matrixV().transpose();
    fit.translation = md - fit.rotation * ms;
  }
  Residuals(src, dst, &fit);
  return fit;
}

}  // namespace hpose
