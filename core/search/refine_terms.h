#ifndef HPOSE_CORE_SEARCH_REFINE_TERMS_H_
#define HPOSE_CORE_SEARCH_REFINE_TERMS_H_

// The terms of the refinement's objective, one point at a time, shared by its two evaluations
// (RefineObjective, prepared once per refinement, and LineariseReference, recomputed from
// scratch at every pose) so that both add exactly the same arithmetic. Units: metres, radians.

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Core>

#include "core/common/pose2d.h"
#include "core/search/pose_refiner.h"

namespace hpose {

// One linearisation of the objective at a pose: normal equations of (x, y, theta) and the
// evidence.
struct Linearisation {
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  Eigen::Vector3d g = Eigen::Vector3d::Zero();
  PoseEvidence evidence;
  // False when the evaluation stopped as soon as its cost exceeded the bound it was given (then
  // h, g and the evidence are partial, and the cost is a lower bound of the full one).
  bool complete = true;
};

namespace refine_terms {

// Squared axial sigma of a Kinect depth z (noise plus the rounding of the disparity step).
inline double AxialVariance(double z, const RefineOptions& o) {
  const double z2 = z * z;
  const double a = o.axial_coeff * z2;
  const double step = o.step_coeff * z2;
  return a * a + step * step / 12.0;
}

// What a template point costs where the sensor got no return at all: as much as one seen
// through by three sigmas more than the free-space margin (a Huber cost of 3 - 1/2).
constexpr double kNoReturnCost = 2.5;

// Template points this near the sensor's optical plane (sensor z, m) or behind it take no part.
constexpr double kMinViewDepth = 0.05;

// A cluster point as the objective reads it; nothing here depends on the pose.
struct DataPoint {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();    // ground frame.
  Eigen::Vector3d ps = Eigen::Vector3d::Zero();   // sensor frame.
  Eigen::Vector3d ray = Eigen::Vector3d::Zero();  // ps normalised.
  double axial_var = 0.0;                         // m^2 at its depth.
  double lateral = 0.0;                           // lateral sigma at its depth (m).
  double gate = 0.0;                              // association radius (m).
  // Inverse variances of an offset along the ray and across it (noise plus the template's
  // own error), for the noise-aware association.
  double inv_along_var = 0.0, inv_across_var = 0.0;
  double unexplained_cost = 0.0;  // its cost when nothing is within the gate.
};

inline DataPoint MakeDataPoint(const Eigen::Vector3f& point, const Eigen::Isometry3d& s_from_g,
                               const RefineOptions& o) {
  DataPoint d;
  d.p = point.cast<double>();
  d.ps = s_from_g * d.p;
  d.ray = d.ps.normalized();
  const double z = std::max(0.1, d.ps.z());
  d.axial_var = AxialVariance(z, o);
  d.lateral = o.lateral_rad * z;
  d.gate = std::max(o.association_gate_m, 4.0 * std::sqrt(d.axial_var));
  d.inv_along_var = 1.0 / (d.axial_var + o.model_sigma_m * o.model_sigma_m);
  d.inv_across_var = 1.0 / (d.lateral * d.lateral + o.model_sigma_m * o.model_sigma_m);
  // Unexplained: costs what a point at the gate would (so poses that leave points unmatched
  // are not cheaper).
  const double k2 = o.cauchy_scale * o.cauchy_scale;
  const double model_var = o.model_sigma_m * o.model_sigma_m;
  d.unexplained_cost = 0.5 * k2 * std::log1p(d.gate * d.gate / (d.axial_var + model_var) / k2);
  return d;
}

// The stride that keeps at most max_data_points of `n` cluster points.
inline size_t DataStride(size_t n, const RefineOptions& o) {
  return std::max<size_t>(1, (n + o.max_data_points - 1) / std::max(1, o.max_data_points));
}

// How far a template point lies from cluster point `d` when choosing which to match it with: the
// offset (dx, dy, dz) = template - cluster point (sensor frame), whose squared length is d2.
// Nearest in space (the squared distance), or with noise-aware association the offset in units
// of the point's noise: along its ray over the axial sigma, across it over the lateral one. A
// Kinect point's error lies almost wholly along its ray (at 3.5 m, 17 mm against 5 mm), so the
// nearest point in space is biased: on a surface oblique to the ray, a point measured too far
// is matched with template surface displaced one way along the surface, one measured too near
// the other way, and near an edge only one of them finds surface within the gate.
inline double AssociationDistance(const DataPoint& d, double dx, double dy, double dz, double d2,
                                  const RefineOptions& o) {
  if (!o.noise_aware_association) return d2;
  const double along = dx * d.ray.x() + dy * d.ray.y() + dz * d.ray.z();
  const double across2 = std::max(0.0, d2 - along * along);
  return along * along * d.inv_along_var + across2 * d.inv_across_var;
}

// Template point `m` rotated by (c, s) = (cos, sin) of the heading about z (not translated).
inline Eigen::Vector3d RotateZ(double c, double s, const Eigen::Vector3d& m) {
  return Eigen::Vector3d(c * m.x() - s * m.y(), s * m.x() + c * m.y(), m.z());
}

// Adds a cluster point matched with the template point `m_rot` (rotated into the ground axes,
// not translated) whose normal is `n` (ground axes): a Cauchy term on its point-to-plane
// distance, weighted by the Kinect noise along the normal, and its derivative (the heading's
// moment arm from `m_rot` or from the point, RefineOptions::noise_free_heading_arm). `a`:
// sensor_from_ground rotation.
inline void AddDataTerm(const DataPoint& d, const Pose2D& pose, const Eigen::Vector3d& m_rot,
                        const Eigen::Vector3d& n, const Eigen::Matrix3d& a, const RefineOptions& o,
                        Linearisation* lin) {
  const double model_var = o.model_sigma_m * o.model_sigma_m;
  const double k2 = o.cauchy_scale * o.cauchy_scale;
  const Eigen::Vector3d e(d.p.x() - pose.x, d.p.y() - pose.y, d.p.z());  // p - t.
  const double r = n.dot(e - m_rot);
  // Noise of this point along the normal: axial along the ray, lateral across it.
  const double cos_ray = std::abs((a * n).dot(d.ray));
  const double var = d.axial_var * cos_ray * cos_ray +
                     d.lateral * d.lateral * (1.0 - cos_ray * cos_ray) + model_var;
  const double u2 = r * r / var;
  if (u2 < 9.0) ++lin->evidence.data_inliers;
  lin->evidence.cost += 0.5 * k2 * std::log1p(u2 / k2);
  const double w = 1.0 / (var * (1.0 + u2 / k2));
  const Eigen::Vector3d& arm = o.noise_free_heading_arm ? m_rot : e;
  const Eigen::Vector3d j(-n.x(), -n.y(), n.x() * arm.y() - n.y() * arm.x());
  lin->h += w * j * j.transpose();
  lin->g += w * r * j;
}

// Adds a visible template point in view at sensor depth `zm` where the sensor saw `seen` (0: no
// return) around its ray: confirmed, hidden by something nearer, without a return (a fixed
// cost), or seen through (a one-sided Huber cost on the excess depth that pulls it back behind
// the surface). `m`: the template point (template frame), rotated by (c, s) = (cos, sin) of the
// heading for the Jacobian; `a` as in AddDataTerm. `on_limb`: the point is on a free limb (it
// is counted in the limbs_ counts too).
inline void AddViewTerm(double seen, double zm, double c, double s, const Eigen::Vector3d& m,
                        bool on_limb, const Eigen::Matrix3d& a, const RefineOptions& o,
                        Linearisation* lin) {
  PoseEvidence& ev = lin->evidence;
  ++ev.model_visible;
  if (seen <= 0.0) {
    if (zm > o.min_return_depth_m && zm < o.max_return_depth_m) {
      ++ev.model_no_return;
      ev.limbs_no_return += on_limb;
      ev.cost += kNoReturnCost;
    }
    return;
  }
  const double model_var = o.model_sigma_m * o.model_sigma_m;
  const double sigma = std::sqrt(AxialVariance(seen, o) + model_var);
  const double r = seen - zm;
  if (r < -o.occluded_sigmas * sigma) {
    ++ev.model_occluded;
    return;
  }
  if (r <= o.free_sigmas * sigma) {
    ++ev.model_seen;
    ev.limbs_seen += on_limb;
    return;
  }
  ++ev.model_free;
  ev.limbs_free += on_limb;
  const double excess = r - o.free_sigmas * sigma;
  const double w = excess < sigma ? 1.0 / (sigma * sigma) : 1.0 / (sigma * excess);
  ev.cost += excess < sigma ? 0.5 * excess * excess / (sigma * sigma) : excess / sigma - 0.5;
  // d(excess)/d(pose) = -d(z_model)/d(pose).
  const Eigen::Vector3d m_rot = RotateZ(c, s, m);
  const Eigen::Vector3d j(-a(2, 0), -a(2, 1), -(a(2, 0) * -m_rot.y() + a(2, 1) * m_rot.x()));
  lin->h += w * j * j.transpose();
  lin->g += w * excess * j;
}

}  // namespace refine_terms
}  // namespace hpose

#endif  // HPOSE_CORE_SEARCH_REFINE_TERMS_H_
