#ifndef HPOSE_CORE_STEREO_RIGID_FIT_H_
#define HPOSE_CORE_STEREO_RIGID_FIT_H_

#include <array>
#include <vector>

#include <Eigen/Core>

#include "core/common/status.h"

namespace hpose {

// A transform dst = rotation * src + translation fitted to point correspondences, with how
// well it fits. For the closed form `rotation` need not be orthonormal (see below).
struct RigidFit {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();  // metres.
  double rms_residual_m = 0.0;  // RMS of |rotation * src_i + translation - dst_i|.
  double max_residual_m = 0.0;
  double orthonormality_error = 0.0;  // Frobenius norm of rotation^T rotation - I.
};

// The smallest sine of the angle between the two edges at any vertex of a triangle, a
// measure of how far from collinear three points are (0 = collinear, 0.866 = equilateral).
double TriangleMinSine(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                       const Eigen::Vector3d& c);

// The paper's closed form from exactly three points: in each frame the basis
// ((p1-p0)/|.|, (p2-p0)/|.|, n/|n|) with n = (p2-p0) x (p1-p0); rotation = B_dst * B_src^-1,
// translation = dst0 - rotation * src0. Exact for noise-free points; under noise the basis is
// not orthonormal, so neither is `rotation` (reported in orthonormality_error).
// Fails with kFailedPrecondition when either triple is (nearly) collinear: TriangleMinSine
// below `min_sine`.
Result<RigidFit> FitRigidClosedForm(const std::array<Eigen::Vector3d, 3>& src,
                                    const std::array<Eigen::Vector3d, 3>& dst,
                                    double min_sine = 0.1);

// Least-squares rotation and translation (Kabsch/Horn/Umeyama without scale: the SVD of the 3x3
// cross-covariance of the centred pairs) for three or more points; always a proper rotation.
// With `weights` (one positive weight per pair) the weighted least-squares problem is solved.
// Fails with kInvalidArgument for fewer than 3 points, different counts, non-finite values or
// non-positive weights, and kFailedPrecondition when the source points are (nearly) collinear.
Result<RigidFit> FitRigidSvd(const std::vector<Eigen::Vector3d>& src,
                             const std::vector<Eigen::Vector3d>& dst, double min_sine = 0.1,
                             const std::vector<double>& weights = {});

// Maximum-likelihood rigid transform when the source points carry Gaussian noise of known
// covariance (e.g. stereo triangulation: much larger along the line of sight) and the
// destination points are exact: minimises sum_i r_i^T (R C_i R^T)^-1 r_i with
// r_i = R src_i + t - dst_i by Gauss-Newton from the (unweighted) SVD solution.
// `src_covariance` holds one symmetric positive-definite matrix per point (m^2). Fails like
// FitRigidSvd, and with kInvalidArgument for a missing or non-positive-definite covariance.
Result<RigidFit> FitRigidCovariance(const std::vector<Eigen::Vector3d>& src,
                                    const std::vector<Eigen::Vector3d>& dst,
                                    const std::vector<Eigen::Matrix3d>& src_covariance,
                                    double min_sine = 0.1);

}  // namespace hpose

#endif  // HPOSE_CORE_STEREO_RIGID_FIT_H_
