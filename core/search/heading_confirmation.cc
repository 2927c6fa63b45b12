#include "core/search/heading_confirmation.h"

#include <cmath>

#include "core/search/fit_summary.h"

namespace hpose {

bool ConfirmsPreviousHeading(const SurfaceModel& model, const Observation& obs, const Pose2D& start,
                             const Pose2D& pose, const FitSummary& fit, double previous_theta,
                             const HeadingConfirmOptions& options, const RefineOptions& refine) {
  if (!(options.within_rad > 0.0) || !(options.far_behind_sigmas > 0.0)) return false;
  if (!(fit.fit >= options.min_fit)) return false;
  if (!(std::abs(AngleDiff(pose.theta, previous_theta)) <= options.within_rad)) return false;
  // The refinement clamps a step at its basin's bound (RefinePose): a pose there lies on it,
  // within rounding.
  constexpr double kOnTheBound = 1.0 - 1e-6;
  if (std::hypot(pose.x - start.x, pose.y - start.y) >= kOnTheBound * refine.max_shift_m ||
      std::abs(AngleDiff(pose.theta, start.theta)) >= kOnTheBound * refine.max_turn_rad) {
    return false;
  }
  const Pose2D turned{pose.x, pose.y, NormalizeAngle(pose.theta + kPi)};
  const FitSummary turned_fit = Summarise(EvaluatePose(model, obs, turned, refine));
  return FarAhead(fit, turned_fit, options.far_behind_sigmas);
}

}  // namespace hpose
