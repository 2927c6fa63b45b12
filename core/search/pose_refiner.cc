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

// The model side of `all` (the whole template's evidence) without what `limbs` (its free limbs'
// own, at the same pose) counts: the template points the frame judges, the limbs left out. The
// data side and the cost stay the whole's.
PoseEvidence WithoutLimbsJudged(PoseEvidence all, const PoseEvidence& limbs) {
  all.model_visible = std::max(0, all.model_visible - limbs.model_visible);
  all.model_seen = std::max(0, all.model_seen - limbs.model_seen);
  all.model_free = std::max(0, all.model_free - limbs.model_free);
  all.model_no_return = std::max(0, all.model_no_return - limbs.model_no_return);
  all.model_occluded = std::max(0, all.model_occluded - limbs.model_occluded);
  return all;
}

}  // namespace

RefinedPose RefinePose(const SurfaceModel& model, const Observation& obs, const Pose2D& start,
                       const RefineOptions& o) {
  RefinedPose out = RefineOnSurface(model, obs, start, o);
  const SurfaceModel* limbs = model.free_limbs();
  if (!o.enabled || !o.refit_without_moved_limbs || limbs == nullptr) return out;
  // The free limbs where the whole fitted, against the rest of the template: a robot that holds
  // them as the template does has them confirmed as the rest (a robot lower than its template
  // contradicts both alike).
  const PoseEvidence seen = EvaluatePose(*limbs, obs, out.pose, o);
  ++out.evaluations;
  const PoseEvidence rest = WithoutLimbsJudged(out.evidence, seen);
  const int judged = seen.model_seen + seen.model_free + seen.model_no_return;
  const int rest_judged = rest.model_seen + rest.model_free + rest.model_no_return;
  const double rest_contradicted = rest_judged > 0 ? rest.Contradicted() : 0.0;
  if (judged < o.moved_limb_min_points ||
      seen.Contradicted() <= rest_contradicted + o.moved_limb_contradicted) {
    return out;
  }
  RefinedPose again = RefineOnSurface(*model.without_free_limbs(), obs, start, o);
  // The evidence stays the first fit's: how well the whole template, limbs and all, explains the
  // cluster where it fits best, so that whether the cluster passes as a humanoid and which
  // template is taken stay as they were. At the new pose the limbs held otherwise would count
  // against the robot (a Darwin-OP with its arms swung fitted 64 there instead of 79, and 6 of
  // 23 such robots failed the gates), and without them the template explains less of the robot.
  again.evidence = out.evidence;
  again.iterations += out.iterations;
  again.evaluations += out.evaluations;
  again.free_limbs_left_out = true;
  return again;
}

}  // namespace hpose
