#include "core/search/pose_refiner.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Cholesky>

namespace hpose {
namespace {

// Squared axial sigma of a Kinect depth z (noise plus the rounding of the disparity step).
double AxialVariance(double z, const RefineOptions& o) {
  const double z2 = z * z;
  const double a = o.axial_coeff * z2;
  const double step = o.step_coeff * z2;
  return a * a + step * step / 12.0;
}

// The template's surface as the sensor sees it at a pose: its points placed in the ground frame
// and a z-buffer of them in the sensor's view (bins of 1.5 surface cells at the template's
// distance) that keeps the nearest point of each bin, so hidden surface (the back, a torso behind
// an arm) takes no part.
class ModelView {
 public:
  ModelView(const SurfaceModel& model, const Pose2D& pose, const Eigen::Isometry3d& s_from_g)
      : model_(model), c_(std::cos(pose.theta)), s_(std::sin(pose.theta)) {
    const std::vector<Eigen::Vector3f>& pts = model.points();
    rotated_.resize(pts.size());
    in_sensor_.resize(pts.size());
    const Eigen::Vector3d t(pose.x, pose.y, 0.0);
    for (size_t i = 0; i < pts.size(); ++i) {
      const Eigen::Vector3d m = pts[i].cast<double>();
      rotated_[i] = Eigen::Vector3d(c_ * m.x() - s_ * m.y(), s_ * m.x() + c_ * m.y(), m.z());
      in_sensor_[i] = s_from_g * (rotated_[i] + t);
    }
    const Eigen::Vector3d centre = s_from_g * (Rotate(model.centre().cast<double>()) + t);
    bin_ = 1.5 * model.spacing_m() / std::max(0.3, centre.norm());
    lo_ = Eigen::Vector2i(1 << 29, 1 << 29);
    Eigen::Vector2i hi(-(1 << 29), -(1 << 29));
    for (const Eigen::Vector3d& p : in_sensor_) {
      if (!(p.z() > 0.05)) continue;
      const Eigen::Vector2i b = Bin(p);
      lo_ = lo_.cwiseMin(b);
      hi = hi.cwiseMax(b);
    }
    if (lo_.x() > hi.x()) return;
    w_ = hi.x() - lo_.x() + 1;
    h_ = hi.y() - lo_.y() + 1;
    if (static_cast<long>(w_) * h_ > 4000000L) {  // degenerate geometry: nothing visible.
      w_ = h_ = 0;
      return;
    }
    winner_.assign(static_cast<size_t>(w_) * h_, -1);
    for (size_t i = 0; i < in_sensor_.size(); ++i) {
      if (!(in_sensor_[i].z() > 0.05)) continue;
      int& wi = winner_[Index(Bin(in_sensor_[i]))];
      if (wi < 0 || in_sensor_[i].z() < in_sensor_[wi].z()) wi = static_cast<int>(i);
    }
    for (int wi : winner_) {
      if (wi >= 0) visible_.push_back(wi);
    }
  }

  // The visible template point nearest to `p_sensor` among the bins around its ray, within
  // `gate` metres, or -1.
  int Associate(const Eigen::Vector3d& p_sensor, double gate) const {
    if (w_ == 0 || !(p_sensor.z() > 0.05)) return -1;
    const Eigen::Vector2i b = Bin(p_sensor) - lo_;
    int best = -1;
    double best_d2 = gate * gate;
    for (int y = std::max(0, b.y() - 1); y <= std::min(h_ - 1, b.y() + 1); ++y) {
      for (int x = std::max(0, b.x() - 1); x <= std::min(w_ - 1, b.x() + 1); ++x) {
        const int wi = winner_[static_cast<size_t>(y) * w_ + x];
        if (wi < 0) continue;
        const double d2 = (in_sensor_[wi] - p_sensor).squaredNorm();
        if (d2 < best_d2) {
          best_d2 = d2;
          best = wi;
        }
      }
    }
    return best;
  }

  Eigen::Vector3d Rotate(const Eigen::Vector3d& v) const {
    return Eigen::Vector3d(c_ * v.x() - s_ * v.y(), s_ * v.x() + c_ * v.y(), v.z());
  }
  // Point i rotated into the ground frame's axes (not translated), and in the sensor frame.
  const Eigen::Vector3d& rotated(int i) const { return rotated_[i]; }
  const Eigen::Vector3d& in_sensor(int i) const { return in_sensor_[i]; }
  Eigen::Vector3d normal_ground(int i) const { return Rotate(model_.normals()[i].cast<double>()); }
  const std::vector<int>& visible() const { return visible_; }

 private:
  Eigen::Vector2i Bin(const Eigen::Vector3d& p) const {
    return Eigen::Vector2i(static_cast<int>(std::floor(p.x() / p.z() / bin_)),
                           static_cast<int>(std::floor(p.y() / p.z() / bin_)));
  }
  size_t Index(const Eigen::Vector2i& b) const {
    return static_cast<size_t>(b.y() - lo_.y()) * w_ + (b.x() - lo_.x());
  }

  const SurfaceModel& model_;
  double c_, s_;
  double bin_ = 0.01;
  std::vector<Eigen::Vector3d> rotated_, in_sensor_;
  Eigen::Vector2i lo_;
  int w_ = 0, h_ = 0;
  std::vector<int> winner_;
  std::vector<int> visible_;
};

// What a template point costs where the sensor got no return at all: as much as one seen
// through by three sigmas more than the free-space margin (a Huber cost of 3 - 1/2).
constexpr double kNoReturnCost = 2.5;

// One linearisation of the objective at a pose: normal equations and the evidence.
struct Linearisation {
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  Eigen::Vector3d g = Eigen::Vector3d::Zero();
  PoseEvidence evidence;
};

Linearisation Linearise(const SurfaceModel& model, const Observation& obs, const Pose2D& pose,
                        const RefineOptions& o) {
  Linearisation lin;
  PoseEvidence& ev = lin.evidence;
  const Eigen::Matrix3d a = obs.sensor_from_ground.linear();
  const double model_var = o.model_sigma_m * o.model_sigma_m;
  const ModelView view(model, pose, obs.sensor_from_ground);

  // Cluster points to the visible template surface (point to plane).
  const std::vector<Eigen::Vector3f>& data = *obs.cluster_points;
  const size_t stride =
      std::max<size_t>(1, (data.size() + o.max_data_points - 1) / std::max(1, o.max_data_points));
  const double k2 = o.cauchy_scale * o.cauchy_scale;
  for (size_t k = 0; k < data.size(); k += stride) {
    const Eigen::Vector3d p = data[k].cast<double>();
    ++ev.data_points;
    const Eigen::Vector3d ps = obs.sensor_from_ground * p;
    const double z = std::max(0.1, ps.z());
    const double axial_var = AxialVariance(z, o);
    const double gate = std::max(o.association_gate_m, 4.0 * std::sqrt(axial_var));
    const int idx = view.Associate(ps, gate);
    if (idx < 0) {
      // Unexplained: costs what a point at the gate would (so poses that leave points
      // unmatched are not cheaper).
      ev.cost += 0.5 * k2 * std::log1p(gate * gate / (axial_var + model_var) / k2);
      continue;
    }
    const Eigen::Vector3d n = view.normal_ground(idx);
    const Eigen::Vector3d e(p.x() - pose.x, p.y() - pose.y, p.z());  // p - t.
    const double r = n.dot(e - view.rotated(idx));
    // Noise of this point along the normal: axial along the ray, lateral across it.
    const double cos_ray = std::abs((a * n).dot(ps.normalized()));
    const double lateral = o.lateral_rad * z;
    const double var =
        axial_var * cos_ray * cos_ray + lateral * lateral * (1.0 - cos_ray * cos_ray) + model_var;
    const double u2 = r * r / var;
    if (u2 < 9.0) ++ev.data_inliers;
    ev.cost += 0.5 * k2 * std::log1p(u2 / k2);
    const double w = 1.0 / (var * (1.0 + u2 / k2));
    const Eigen::Vector3d j(-n.x(), -n.y(), n.x() * e.y() - n.y() * e.x());
    lin.h += w * j * j.transpose();
    lin.g += w * r * j;
  }

  // Visible template points against what the sensor saw along their rays.
  for (int i : view.visible()) {
    const Eigen::Vector3d& ps = view.in_sensor(i);
    if (!obs.range->Covers(ps)) continue;
    ++ev.model_visible;
    const double zm = ps.z();
    const double seen = obs.range->NearestAround(ps, 1);
    if (seen <= 0.0) {
      if (zm > o.min_return_depth_m && zm < o.max_return_depth_m) {
        ++ev.model_no_return;
        ev.cost += kNoReturnCost;
      }
      continue;
    }
    const double sigma = std::sqrt(AxialVariance(seen, o) + model_var);
    const double r = seen - zm;
    if (r < -o.occluded_sigmas * sigma) {
      ++ev.model_occluded;
      continue;
    }
    if (r <= o.free_sigmas * sigma) {
      ++ev.model_seen;
      continue;
    }
    ++ev.model_free;
    // Seen through: a Huber cost on the excess depth pulls the point back behind the surface.
    const double excess = r - o.free_sigmas * sigma;
    const double w = excess < sigma ? 1.0 / (sigma * sigma) : 1.0 / (sigma * excess);
    ev.cost += excess < sigma ? 0.5 * excess * excess / (sigma * sigma) : excess / sigma - 0.5;
    // d(excess)/d(pose) = -d(z_model)/d(pose).
    const Eigen::Vector3d& m = view.rotated(i);
    const Eigen::Vector3d j(-a(2, 0), -a(2, 1), -(a(2, 0) * -m.y() + a(2, 1) * m.x()));
    lin.h += w * j * j.transpose();
    lin.g += w * excess * j;
  }
  return lin;
}

}  // namespace

double PoseEvidence::Explained() const {
  return data_points > 0 ? static_cast<double>(data_inliers) / data_points : 0.0;
}

double PoseEvidence::Contradicted() const {
  const int judged = model_seen + model_free + model_no_return;
  return judged > 0 ? static_cast<double>(model_free + model_no_return) / judged : 1.0;
}

double PoseEvidence::Fit() const { return 100.0 * Explained() * (1.0 - Contradicted()); }

PoseEvidence EvaluatePose(const SurfaceModel& model, const Observation& obs, const Pose2D& pose,
                          const RefineOptions& options) {
  return Linearise(model, obs, pose, options).evidence;
}

RefinedPose RefinePose(const SurfaceModel& model, const Observation& obs, const Pose2D& start,
                       const RefineOptions& o) {
  RefinedPose out;
  out.pose = start;
  Linearisation lin = Linearise(model, obs, start, o);
  if (!o.enabled) {
    out.evidence = lin.evidence;
    return out;
  }
  double lambda = 1e-3;
  for (int it = 0; it < o.max_iterations; ++it) {
    out.iterations = it + 1;
    Eigen::Matrix3d damped = lin.h;
    for (int k = 0; k < 3; ++k) damped(k, k) += lambda * std::max(lin.h(k, k), 1e-9) + 1e-12;
    const Eigen::Vector3d step = damped.ldlt().solve(-lin.g);
    if (!step.allFinite()) break;
    Pose2D next{out.pose.x + step.x(), out.pose.y + step.y(), out.pose.theta + step.z()};
    // Stay in the basin of the lattice optimum.
    Eigen::Vector2d shift(next.x - start.x, next.y - start.y);
    bool limited = false;
    if (shift.norm() > o.max_shift_m) {
      shift *= o.max_shift_m / shift.norm();
      limited = true;
    }
    double turn = AngleDiff(next.theta, start.theta);
    if (std::abs(turn) > o.max_turn_rad) {
      turn = std::copysign(o.max_turn_rad, turn);
      limited = true;
    }
    next = Pose2D{start.x + shift.x(), start.y + shift.y(), NormalizeAngle(start.theta + turn)};
    Linearisation trial = Linearise(model, obs, next, o);
    if (trial.evidence.cost <= lin.evidence.cost + 1e-9) {
      const double moved = std::hypot(next.x - out.pose.x, next.y - out.pose.y);
      const double turned = std::abs(AngleDiff(next.theta, out.pose.theta));
      out.pose = next;
      out.at_basin_limit = limited;
      lin = std::move(trial);
      lambda = std::max(1e-6, lambda * 0.3);
      if (moved < 2e-4 && turned < 3.5e-4) {
        out.converged = true;
        break;
      }
    } else {
      lambda *= 10.0;
      if (lambda > 1e4) {
        out.converged = true;  // no descent left: a minimum within the basin.
        break;
      }
    }
  }
  out.evidence = lin.evidence;
  // Covariance: inverse information, inflated when residuals are wider than the noise model.
  const Eigen::Matrix3d h = lin.h + 1e-12 * Eigen::Matrix3d::Identity();
  const int n = std::max(1, lin.evidence.data_inliers + lin.evidence.model_free - 3);
  const double scale = std::max(1.0, 2.0 * lin.evidence.cost / n);
  out.covariance = scale * h.inverse();
  return out;
}

}  // namespace hpose
