#include "core/search/pose_refiner.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include <Eigen/Cholesky>

#include "core/search/refine_objective.h"

namespace hpose {
namespace {

// The objective at the poses of one refinement: the prepared evaluation (RefineObjective) by
// default, or the reference one when the options ask for it.
class RefineEvaluator {
 public:
  RefineEvaluator(const SurfaceModel& model, const Observation& obs, const RefineOptions& o)
      : model_(model), obs_(obs), options_(o) {
    if (!o.reference_evaluation) prepared_.emplace(model, obs, o);
  }

  // The linearisation at `pose`; the prepared evaluation may stop early (incomplete) once the
  // cost exceeds `stop_above`.
  Linearisation At(const Pose2D& pose,
                   double stop_above = std::numeric_limits<double>::infinity()) {
    if (prepared_) return prepared_->Linearise(pose, stop_above);
    return LineariseReference(model_, obs_, pose, options_);
  }

 private:
  const SurfaceModel& model_;
  const Observation& obs_;
  const RefineOptions& options_;
  std::optional<RefineObjective> prepared_;
};

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
  return RefineEvaluator(model, obs, options).At(pose).evidence;
}

namespace {

// The refinement on one surface (RefinePose without the second fit).
RefinedPose RefineOnSurface(const SurfaceModel& model, const Observation& obs, const Pose2D& start,
                            const RefineOptions& o) {
  RefinedPose out;
  out.pose = start;
  RefineEvaluator evaluate(model, obs, o);
  Linearisation lin = evaluate.At(start);
  out.evaluations = 1;
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
    const bool tiny = o.stop_at_tiny_step && std::hypot(step.x(), step.y()) < o.converged_shift_m &&
                      std::abs(step.z()) < o.converged_turn_rad;
    if (tiny || step.dot(lin.h * step) < o.converged_sigmas * o.converged_sigmas) {
      out.converged = true;
      break;
    }
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
    // A trial costing more than this is rejected: its evaluation may stop as soon as it does.
    const double accept_below = lin.evidence.cost + 1e-9;
    Linearisation trial = evaluate.At(next, accept_below);
    ++out.evaluations;
    if (trial.complete && trial.evidence.cost <= accept_below) {
      const double moved = std::hypot(next.x - out.pose.x, next.y - out.pose.y);
      const double turned = std::abs(AngleDiff(next.theta, out.pose.theta));
      out.pose = next;
      out.at_basin_limit = limited;
      lin = std::move(trial);
      lambda = std::max(1e-6, lambda * 0.3);
      if (moved < o.converged_shift_m && turned < o.converged_turn_rad) {
        out.converged = true;
        break;
      }
    } else {
      // At a small damping ten times as much proposes almost the same step again (rejected
      // again): start the retries where the step is about halved.
      lambda = std::max(lambda * 10.0, o.min_retry_damping);
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
  const Eigen::Vector3d at =
      obs.sensor_from_ground * Eigen::Vector3d(out.pose.x, out.pose.y, model.centre().z());
  const double shared = o.covariance_scale_at_sensor + o.covariance_scale_per_m2 * at.squaredNorm();
  out.covariance = shared * scale * h.inverse();
  return out;
}

}  // namespace

RefinedPose RefinePose(const SurfaceModel& model, const Observation& obs, const Pose2D& start,
                       const RefineOptions& o) {
  RefinedPose out = RefineOnSurface(model, obs, start, o);
  if (!o.enabled || !o.refit_without_moved_limbs || model.free_limb_marks().empty()) return out;
  // The free limbs where the whole fitted, against the rest of the template: a robot that holds
  // them as the template does has them confirmed as the rest (a robot lower than its template
  // contradicts both alike). The fit's own evidence counts them.
  const PoseEvidence& e = out.evidence;
  const int judged = e.limbs_seen + e.limbs_free + e.limbs_no_return;
  const int contradicted = e.limbs_free + e.limbs_no_return;
  const int rest_judged = e.model_seen + e.model_free + e.model_no_return - judged;
  const int rest_contradicted = e.model_free + e.model_no_return - contradicted;
  const double rest_share =
      rest_judged > 0 ? static_cast<double>(rest_contradicted) / rest_judged : 0.0;
  out.free_limbs_moved =
      judged >= o.moved_limb_min_points &&
      static_cast<double>(contradicted) / judged > rest_share + o.moved_limb_contradicted;
  return out;
}

RefinedPose RefineWithoutFreeLimbs(const SurfaceModel& model, const Observation& obs,
                                   const Pose2D& start, const RefineOptions& o) {
  const SurfaceModel* rest = model.without_free_limbs();
  RefinedPose out = RefineOnSurface(rest != nullptr ? *rest : model, obs, start, o);
  out.free_limbs_left_out = rest != nullptr;
  return out;
}

}  // namespace hpose
