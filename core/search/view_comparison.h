#ifndef HPOSE_CORE_SEARCH_VIEW_COMPARISON_H_
#define HPOSE_CORE_SEARCH_VIEW_COMPARISON_H_

#include "core/common/pose2d.h"
#include "core/search/pose_refiner.h"
#include "core/search/surface_model.h"

namespace hpose {

// Which of two poses of one template (typically a heading and its front/back flip) the depth
// image supports, judged on the whole visible surface the sensor should see at each pose: the
// template's expected depth image (its surface, self-occlusion by a z-buffer) against what the
// sensor saw along the same rays. Unlike the refinement's evidence it does not stop at the
// cluster: the feet and whatever else lies in the floor band that clustering drops take part,
// and a template surface the sensor saw *nearer* than expected counts against a pose as much as
// one seen through (a foot pointing the other way is 2-3 cm off either way).
//
// The rays are a grid of bins of about 1.5 template surface cells at the template's distance
// over what either pose covers, the same for both; rays without a return are skipped. A ray's
// return is foreground when it lies on a covering pose's surface or nearer, background when it
// lies behind both. A pose's cost on a ray is a truncated Gaussian of the depth residual with
// the Kinect v1 axial noise (RefineOptions' noise model), 0.5 min((d - z)^2 / sigma^2, T), where
// it covers the ray; where it does not, nothing for a background return and T / 2 for a
// foreground one (a return it does not explain). Each pose first settles where its cost is
// least nearby (ViewComparisonOptions), then the costs are paired ray by ray, so the noise they
// share cancels and the standard error of the difference comes from the spread of the per-ray
// differences.
struct ViewComparison {
  int rays = 0;  // rays compared (covered by either pose, with a return).
  // Sum over rays of cost(b) - cost(a) (nats): positive favours `a`.
  double log_likelihood_ratio = 0.0;
  // Standard error of that sum, from the paired per-ray differences (nats).
  double sigma = 0.0;
  // Where each pose fits the depth image best near where it was given (the poses compared),
  // and what the rays cost each there (nats).
  Pose2D settled_a, settled_b;
  double cost_a = 0.0, cost_b = 0.0;
  // Expected depth images computed: the settles' trials and the two compared.
  int evaluations = 0;

  // How many standard errors the ratio is from zero (0 without rays).
  double Z() const { return sigma > 0.0 ? log_likelihood_ratio / sigma : 0.0; }
};

struct ViewComparisonOptions {
  // false: the choice between a heading and its runner-up is left to the refined fits alone
  // (the previous behaviour).
  bool enabled = true;
  // The depth images decide between two headings when their log-likelihood ratio is at least
  // this many standard errors from zero; closer, the heading is reported ambiguous.
  double decisive_sigmas = 3.0;
  // When the ratio is not decisive the heading is reported ambiguous, and the pose given is the
  // one the ratio favours, however slightly (true), or the one with the higher refined fit
  // (false, as before). The fits of a heading and its flip are often equal to the last digit
  // on a body whose front and back differ only in its feet; the ratio still leans the right
  // way more often than not (docs/BENCHMARKS.md).
  bool undecided_follow_ratio = true;
  // In a tracked stream the depth images are not asked when the two headings' refined fits both
  // pass as a humanoid (EstimatorOptions::min_humanoid_fit), differ by more than this many
  // standard errors of their difference, and the better one faces within 90 degrees of the
  // previous frame's heading: that one is taken, not ambiguous. There the images could only
  // overturn it by a decisive ratio (an undecided one follows the previous frame), which they
  // never did on the frames measured (docs/BENCHMARKS.md); their comparison took about 0.8 ms a
  // call, 4.7% of a tracked walk's instructions. Cold frames, and a fit below the humanoid fit (the
  // images' choice then says whether the cluster is a humanoid), always ask them. 0: asked whatever
  // the fits (before).
  double max_fit_sigmas = 8.0;
  // Before comparing, each pose settles where the depth image fits it best within this of where
  // it was given (`settle_rounds` steps or rounds at most): refinements on the cluster place
  // two headings a few millimetres apart, which at 1 m weighs more than a foot pointing the
  // other way. 0 rounds: compared where given.
  double settle_shift_m = 0.008;
  double settle_turn_rad = 2.0 * kPi / 180.0;
  int settle_rounds = 10;
  // How: damped Gauss-Newton steps on the rays' depth residuals (true), each taken only when it
  // lowers the cost, until a proposed step is below settle_converged_m and
  // settle_converged_rad; or a pattern search over x, y and theta (false, before: about 27
  // expected depth images per pose against 4-6).
  bool settle_by_gauss_newton = true;
  double settle_converged_m = 2.5e-4;
  double settle_converged_rad = 1e-3;
  // ... or below this many standard errors of the pose by the rays' information (sqrt(d' H d),
  // as RefineOptions::converged_sigmas): the cost would fall by about half its square in nats,
  // against a ratio that decides at 3 standard errors of a sum over hundreds of rays. 0: off
  // (before).
  double settle_converged_sigmas = 1.0;
  // After the Gauss-Newton steps, a pattern search from where they ended with shift steps of
  // this (turn steps in proportion), down to settle_min_step_m: it also weighs the returns a
  // pose leaves uncovered, which the steps do not follow. 0: none (the default; with 1 mm it
  // cost three times the expected depth images for no measurable gain in front/back decisions,
  // docs/BENCHMARKS.md).
  double settle_polish_step_m = 0.0;
  // The pattern search halves its steps after a round without a move and stops once the shift
  // step falls below this (the turn step halves with it: 1 mm with 0.25 deg by default). Finer
  // steps moved a pose by less than a millimetre, a tenth of the Kinect's depth noise at 1 m,
  // and took about a third of the comparison's time. 0: every one of settle_rounds rounds.
  double settle_min_step_m = 0.001;
  // Truncation of the per-ray squared normalised residual (T above): a ray costs at most T / 2.
  double max_squared_residual = 9.0;
};

// Compares poses `a` and `b` (robot frame in the ground frame, on the floor) of `model` against
// the observation's range image. The observation's cluster points are not used. Each pose it
// tries is z-buffered by TemplateProjector's vectorised pass; with `noise.reference_evaluation`
// every point is placed and binned directly instead (the reference, same result to the bit).
ViewComparison CompareViews(const SurfaceModel& model, const Observation& obs, const Pose2D& a,
                            const Pose2D& b, const RefineOptions& noise,
                            const ViewComparisonOptions& options = {});

}  // namespace hpose

#endif  // HPOSE_CORE_SEARCH_VIEW_COMPARISON_H_
