#ifndef HPOSE_CORE_SEARCH_HEADING_CONFIRMATION_H_
#define HPOSE_CORE_SEARCH_HEADING_CONFIRMATION_H_

#include "core/common/pose2d.h"
#include "core/search/estimate.h"
#include "core/search/pose_refiner.h"
#include "core/search/surface_model.h"

namespace hpose {

// What a tracked frame asks of a refined pose before it leaves the pose's runner-up heading
// unsearched (EstimatorOptions::tracked_heading_confirm_rad).
struct HeadingConfirmOptions {
  double within_rad = 0.0;  // of the previous frame's heading; 0: never confirmed.
  double min_fit = 0.0;     // the pose's refined fit at least this (the humanoid's fit).
  // The turned-about pose fits worse by more than this many standard errors of the difference.
  double far_behind_sigmas = 0.0;  // 0: never confirmed.
};

// Whether `pose`, refined from `start` (the search's optimum) with `fit` on a cluster the
// previous frame's humanoid stood on, confirms that frame's heading `previous_theta`: it faces
// within options.within_rad of it, fits at least options.min_fit, the refinement stopped inside
// its basin (short of refine.max_shift_m and refine.max_turn_rad from `start`: at the bound,
// another start, such as the runner-up's, may fit better), and the same place turned about
// (theta + 180 degrees, evaluated where it lies, not refined) fits far behind it. A robot turned
// about between two frames whose search optimum still faces its old way fails the last test: its
// true heading is the turned-about pose, which fits as well or better.
bool ConfirmsPreviousHeading(const SurfaceModel& model, const Observation& obs, const Pose2D& start,
                             const Pose2D& pose, const FitSummary& fit, double previous_theta,
                             const HeadingConfirmOptions& options, const RefineOptions& refine);

}  // namespace hpose

#endif  // HPOSE_CORE_SEARCH_HEADING_CONFIRMATION_H_
