#include "core/stereo/rigid_fit.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
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

Error Collinear() {
  return MakeError(ErrorCode::kFailedPrecondition,
                   "rigid fit: the source points are (nearly) collinear");
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
  if (!weights.empty() && weights.size() != src.size()) {
    return MakeError(ErrorCode::kInvalidArgument, "rigid fit: one weight per point pair needed");
  }
  const size_t n = src.size();
  for (size_t i = 0; i < n; ++i) {
    if (!src[i].allFinite() || !dst[i].allFinite()) {
      return MakeError(ErrorCode::kInvalidArgument, "rigid fit: non-finite point");
    }
    if (!weights.empty() && (!(weights[i] > 0) || !std::isfinite(weights[i]))) {
      return MakeError(ErrorCode::kInvalidArgument, "rigid fit: weights must be positive");
    }
  }
  // Collinearity: the second singular value of the centred source points relative to the first,
  // the square roots of the two largest eigenvalues of their 3x3 scatter. Everything here is
  // 3x3: an SVD of the 3xN points gives the same figures at many times the compile time.
  if (n == 3) {
    if (TriangleMinSine(src[0], src[1], src[2]) < min_sine) return Collinear();
  } else {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& p : src) mean += p;
    mean /= static_cast<double>(n);
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (const Eigen::Vector3d& p : src) scatter += (p - mean) * (p - mean).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(scatter, Eigen::EigenvaluesOnly);
    const Eigen::Vector3d ev = eigen.eigenvalues().cwiseMax(0.0);  // ascending.
    if (ev(2) <= 0 || std::sqrt(ev(1) / ev(2)) < min_sine) return Collinear();
  }
  // Weighted Kabsch (Umeyama without scale when the weights are equal): R = U diag(1, 1, det)
  // V^T from the SVD of the weighted cross-covariance of the centred pairs.
  const auto weight = [&weights](size_t i) { return weights.empty() ? 1.0 : weights[i]; };
  double sum = 0;
  Eigen::Vector3d ms = Eigen::Vector3d::Zero(), md = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    const double w = weight(i);
    sum += w;
    ms += w * src[i];
    md += w * dst[i];
  }
  ms /= sum;
  md /= sum;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    cov += weight(i) * (dst[i] - md) * (src[i] - ms).transpose();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> k(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d fix = Eigen::Matrix3d::Identity();
  if (k.matrixU().determinant() * k.matrixV().determinant() < 0) fix(2, 2) = -1;
  RigidFit fit;
  fit.rotation = k.matrixU() * fix * k.matrixV().transpose();
  fit.translation = md - fit.rotation * ms;
  Residuals(src, dst, &fit);
  return fit;
}

Result<RigidFit> FitRigidCovariance(const std::vector<Eigen::Vector3d>& src,
                                    const std::vector<Eigen::Vector3d>& dst,
                                    const std::vector<Eigen::Matrix3d>& src_covariance,
                                    double min_sine) {
  Result<RigidFit> start = FitRigidSvd(src, dst, min_sine);
  if (!start.ok()) return start;
  if (src_covariance.size() != src.size()) {
    return MakeError(ErrorCode::kInvalidArgument, "rigid fit: one covariance per point needed");
  }
  const int n = static_cast<int>(src.size());
  std::vector<Eigen::Matrix3d> info(n);  // inverse covariances, source frame.
  for (int i = 0; i < n; ++i) {
    const Eigen::LLT<Eigen::Matrix3d> llt(src_covariance[i]);
    if (!src_covariance[i].allFinite() || llt.info() != Eigen::Success) {
      return MakeError(ErrorCode::kInvalidArgument,
                       "rigid fit: covariance " + std::to_string(i) + " is not positive definite");
    }
    info[i] = llt.solve(Eigen::Matrix3d::Identity());
  }
  Eigen::Matrix3d r = start->rotation;
  Eigen::Vector3d t = start->translation;
  // In the source frame the residual is e_i = src_i - R^T (dst_i - t), with covariance C_i.
  // Parameters: a small rotation w (R <- R exp([w])) and a translation step dt.
  for (int iteration = 0; iteration < 20; ++iteration) {
    Eigen::Matrix<double, 6, 6> h = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3d q = r.transpose() * (dst[i] - t);  // dst in the source frame.
      const Eigen::Vector3d e = src[i] - q;
      // d q / d w = [q]x (for R exp([w])), d q / d t = -R^T.
      Eigen::Matrix<double, 3, 6> j;
      Eigen::Matrix3d qx;
      qx << 0, -q.z(), q.y(), q.z(), 0, -q.x(), -q.y(), q.x(), 0;
      j.leftCols<3>() = -qx;
      j.rightCols<3>() = r.transpose();
      h += j.transpose() * info[i] * j;
      g += j.transpose() * info[i] * e;
    }
    const Eigen::Matrix<double, 6, 1> step = -h.ldlt().solve(g);
    if (!step.allFinite()) break;
    const Eigen::Vector3d w = step.head<3>();
    if (w.norm() > 1e-12) r = r * Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
    t += step.tail<3>();
    if (step.norm() < 1e-10) break;
  }
  RigidFit fit;
  fit.rotation = r;
  fit.translation = t;
  Residuals(src, dst, &fit);
  return fit;
}

}  // namespace hpose
