#ifndef HPOSE_CORE_SEARCH_POSE_REFINER_H_
#define HPOSE_CORE_SEARCH_POSE_REFINER_H_

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/common/pose2d.h"
#include "core/depth/range_image.h"
#include "core/search/surface_model.h"

namespace hpose {

class PreparedCluster;

// Continuous refinement of a lattice pose and the evidence that decides between poses and
// templates. Units: metres, radians; poses are the robot frame in the ground frame.
struct RefineOptions {
  bool enabled = true;
  // Damped Gauss-Newton steps at most (most refinements converge in 4-8; a start far from the
  // optimum takes up to ~15).
  int max_iterations = 20;
  // Converged once an accepted step moves the pose by less than this (both).
  double converged_shift_m = 2e-4;
  double converged_turn_rad = 3.5e-4;
  // A proposed step smaller than that ends the refinement without being evaluated (converged).
  // Near the minimum the cost's noise rejects most full steps, and each rejection tried the
  // pose again with ten times the damping, up to 10 evaluations whose steps shrank below a
  // micrometre. false: every step is evaluated (before).
  bool stop_at_tiny_step = true;
  // A proposed step shorter than this many standard errors ends the refinement too, without
  // being evaluated: its length measured by the information matrix H (sqrt(d' H d)). The
  // quadratic model predicts the cost to fall by about half its square (nats), and the pose
  // would move by less than that many standard deviations of its own estimate (the covariance
  // reported is at least H^-1). The cost is not smooth at that scale (the association and the
  // z-buffer change): of such steps 58% were rejected, and they were a quarter of all evaluations.
  // 0: off (before).
  double converged_sigmas = 1.0;
  // A rejected step is tried again with ten times the damping, and at least this much: 1 about
  // halves the step (the damping adds that multiple of the information's diagonal). At the
  // damping of an accepted step (1e-3 and less) ten times as much proposed almost the same step
  // again, rejected again: a third of all evaluations. 0: ten times, whatever it was (before).
  double min_retry_damping = 1.0;
  // The refined pose stays within this of the lattice pose it starts from. Every accepted step
  // lowers the cost, so the refinement stays in the basin it starts in; the bound keeps it well
  // away from the runner-up heading (more than 30 degrees off). Three voxels and 10 degrees: at
  // 3-3.5 m the lattice optimum of the voxel score (16 mm voxels, depth noise 13-17 mm) lies up
  // to ~40 mm and ~8 degrees from the truth; one voxel and 5 degrees (the former bound) stopped
  // such refinements at their edge, 3 degrees and 1-2 cm short (a pull toward the sensor).
  double max_shift_m = 0.048;
  double max_turn_rad = 10.0 * kPi / 180.0;
  // Kinect v1 noise (SPEC §5): axial sigma = axial_coeff z^2; depth step = step_coeff z^2,
  // whose rounding adds step / sqrt(12); lateral sigma = lateral_rad z (0.8 px at 585 px focal).
  double axial_coeff = 1.425e-3;
  double step_coeff = 3.07e-3;
  double lateral_rad = 0.8 / 585.0;
  // Template surface error and the 8 mm grid the cluster points are reduced on.
  double model_sigma_m = 0.003;
  // Robust (Cauchy) scale of normalised point-to-surface residuals.
  double cauchy_scale = 3.0;
  // A visible template point is seen through when the sensor saw farther than it by more than
  // this many sigmas, and consistent within it.
  double free_sigmas = 3.0;
  // Template points nearer than this along the ray than what was seen are hidden by something
  // in front (occluded): they neither support nor contradict the pose.
  double occluded_sigmas = 3.0;
  // Without a return at all where a template point lies in view within the sensor's working
  // range (Kinect v1: 0.8-4 m, SPEC §1), that point is contradicted too.
  double min_return_depth_m = 0.85;
  double max_return_depth_m = 3.8;
  // The runner-up heading is refined too (to tell front from back) when its search score is
  // within this many points of the best's; a poorer one is only evaluated where it lies.
  double runner_up_score_window = 10.0;
  // ... and it is searched for only that far below the best's score: a runner-up farther behind
  // would only be evaluated where it lies, and on the accuracy benchmark's 1 728 frames no such
  // runner-up changed a heading, a template or an ambiguity. None is reported then
  // (Candidate::runner_up_score holds an upper bound of the other headings' scores). The search
  // stops as soon as no other heading can come that near: in the tracked walk 14% fewer bounds
  // at the median, 5% fewer instructions (docs/BENCHMARKS.md). false: searched down to the score
  // threshold (before).
  bool runner_up_within_score_window = true;
  // ... and when its template's refined fit is within this many standard errors of the best
  // template's fit on the same cluster; otherwise it is only evaluated where it lies, as a
  // runner-up far behind in score. A template that far behind (e.g. a fit of 80 against 99,
  // standard errors of about 1.3) would need its other heading to fit better by as much to be
  // chosen. 0: the runner-ups of every template (before).
  double runner_up_fit_sigmas = 3.0;
  // ... and such a template's runner-up is not even searched for: its search stops at the
  // optimum (the runner-up's bounds were about two fifths of a tracked frame's), and it has no
  // runner-up. Should the leading template then take a heading that fits worse (the depth
  // images decide), a template that contends with it after all has its runner-up searched and
  // evaluated. true: every template's runner-up searched, as before.
  bool search_far_behind_runner_up = false;
  // A cluster point is matched with a visible template point around its ray within this or 4
  // axial sigmas, whichever is larger; points with none are unexplained.
  double association_gate_m = 0.03;
  // Which one: the nearest in units of the point's Kinect noise (the offset along its ray over
  // the axial sigma, across it over the lateral one), or with false the nearest in space. A
  // Kinect point's error lies along its ray, so matching by distance in space biases the
  // heading at distance: at 3.5 m, a nao turned 60 degrees came back 2-4 degrees too far
  // turned (docs/BENCHMARKS.md).
  bool noise_aware_association = true;
  // The data term's derivative in the heading takes its moment arm from the matched template
  // point (true) rather than from the cluster point itself (false, the exact derivative of the
  // point-to-plane distance). The cluster point carries its depth noise into the arm, which
  // correlates with the residual: the steps' fixed point then leans toward poses whose surface
  // is more oblique to the rays (more side-on), +1-3 degrees at 3.5 m. From the template point
  // the arm is noise-free and the fixed point is not pulled.
  bool noise_free_heading_arm = true;
  int max_data_points = 800;  // cluster points used (evenly strided).
  // The template surface the refinement fits to is reduced to one point per cell of this edge
  // (SurfaceModel); 0 keeps the template's own surface (8 mm at 16 mm voxels).
  double surface_spacing_m = 0.0;
  // A template that marks its free limbs (VoxelTemplate::free_limb: arms, head) is fitted again
  // without them, from the same start, when the share of their judged points contradicted where
  // the whole template fitted (at least moved_limb_min_points judged) exceeds the rest of the
  // template's share by more than moved_limb_contradicted: the robot holds them otherwise (arms
  // swung while walking), and fitting them turns the whole pose toward them (a Darwin-OP with
  // its arms swung 0.4 rad: 7-8 degrees at the median). Held as in the template they are
  // confirmed like the rest (a share of at most 0.008 in 6 frames), and a robot lower than its
  // template contradicts the limbs and the rest alike. The evidence stays the first fit's.
  // false: one fit (before).
  bool refit_without_moved_limbs = true;
  double moved_limb_contradicted = 0.05;
  int moved_limb_min_points = 20;
  // Evaluate the objective the direct way, everything recomputed at every pose, instead of the
  // prepared evaluation (RefineObjective). Same result, several times slower: the reference
  // that tests and benchmarks compare with.
  bool reference_evaluation = false;
  // The reported covariance is the information matrix's inverse (scaled up where the residuals
  // are wider than the noise model) times covariance_scale_at_sensor + covariance_scale_per_m2
  // r^2, r the distance from the sensor to the template's centre at the pose. The information
  // counts every point's error as its own, but a depth camera's neighbouring pixels share
  // theirs (a Kinect matches a window of its pattern per disparity), as do all points of a
  // template's shape errors, and the refinement stops within about one standard error. With
  // the simulator's errors shared as a real Kinect's, the errors at 1-3.5 m were 2-3.4 times
  // the former standard deviations in x and 1.3-2.6 times in theta, and e' C^-1 e (3 degrees
  // of freedom) had medians of 6.5-17.6 instead of 2.37 (docs/BENCHMARKS.md, "The reported
  // covariance against the errors"). A shared error grows with the points within a correlation
  // window, which grows with r^2. 1 and 0: the former covariance.
  double covariance_scale_at_sensor = 2.5;
  double covariance_scale_per_m2 = 0.4;
};

// What a pose explains of the observation and what contradicts it.
struct PoseEvidence {
  int data_points = 0;        // cluster points considered.
  int data_inliers = 0;       // ... within 3 sigma of the template surface.
  int model_visible = 0;      // template points facing the sensor, in view.
  int model_seen = 0;         // ... whose depth the sensor confirmed (within free_sigmas).
  int model_free = 0;         // ... the sensor saw through.
  int model_no_return = 0;    // ... where the sensor got no return within its range.
  int model_occluded = 0;     // ... hidden behind something nearer.
  int model_out_of_view = 0;  // template points facing the sensor, outside the view.
  // Of model_seen, model_free and model_no_return, the points on the template's free limbs
  // (SurfaceModel::free_limb_marks; 0 without marks).
  int limbs_seen = 0;
  int limbs_free = 0;
  int limbs_no_return = 0;
  // Robust negative log-likelihood of the observation under the pose (nats): Cauchy on the
  // cluster points' normalised distances (unexplained points cost as at the association gate),
  // Huber on seen-through template points, a fixed cost per template point without a return.
  // Differences between poses and templates on the same cluster are log-likelihood ratios.
  double cost = 0.0;

  // Fraction of the cluster the template explains, and of the template's visible surface that
  // the observation contradicts.
  double Explained() const;
  double Contradicted() const;
  // 100 * Explained() * (1 - Contradicted()): the refined, noise-aware score.
  double Fit() const;
};

struct RefinedPose {
  Pose2D pose;
  // Covariance of (x, y, theta) from the Gauss-Newton information matrix (m^2, rad^2), inflated
  // for errors the points share (RefineOptions::covariance_scale_at_sensor, _per_m2).
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  int iterations = 0;
  int evaluations = 0;  // of the objective: the start's and every trial step's.
  bool converged = false;
  bool at_basin_limit = false;  // it stopped at the max_shift_m / max_turn_rad bound.
  // The frame contradicts the template's free limbs at `pose` more than the rest of it
  // (RefineOptions::refit_without_moved_limbs): RefineWithoutFreeLimbs fits the robot better.
  bool free_limbs_moved = false;
  // The pose was fitted without the template's free limbs (RefineWithoutFreeLimbs).
  bool free_limbs_left_out = false;
  PoseEvidence evidence;  // at `pose`.
};

// What the cluster showed: its points (ground frame) and what the sensor saw in every
// direction (a range image of the whole frame in the sensor frame).
struct Observation {
  const std::vector<Eigen::Vector3f>* cluster_points = nullptr;
  const RangeImage* range = nullptr;
  Eigen::Isometry3d sensor_from_ground = Eigen::Isometry3d::Identity();
  // Optional: the cluster's side of the objective made once (PreparedCluster, from these points
  // and mount), shared by the refinements of every template of a cluster. Used when it was made
  // with the same options; otherwise each refinement prepares its own (the same result).
  const PreparedCluster* prepared = nullptr;
};

// Refines `start` (x, y, theta; z fixed on the floor) by robust, noise-weighted Gauss-Newton on
// two terms: cluster points to the template surface (point to plane, each point weighted by the
// Kinect noise along the surface normal), and template points the sensor should see (from its
// position, self-occlusion by a z-buffer) that it saw through (a one-sided cost). Never leaves
// the basin bounds of the options. Returns `start` unchanged with its evidence when disabled.
// With a template that marks free limbs, judges them at the refined pose (free_limbs_moved).
RefinedPose RefinePose(const SurfaceModel& model, const Observation& obs, const Pose2D& start,
                       const RefineOptions& options = {});

// RefinePose from `start` on the template without its free limbs (free_limbs_left_out), for a
// pose whose limbs moved: the robot holds them otherwise than the template. Its evidence is that
// of the template without them; the estimator keeps the whole template's first fit, which decides
// whether the cluster passes as a humanoid and which template is taken. A `model` that marks no
// free limbs is refined whole.
RefinedPose RefineWithoutFreeLimbs(const SurfaceModel& model, const Observation& obs,
                                   const Pose2D& start, const RefineOptions& options = {});

// The evidence for `pose` without moving it.
PoseEvidence EvaluatePose(const SurfaceModel& model, const Observation& obs, const Pose2D& pose,
                          const RefineOptions& options = {});

}  // namespace hpose

#endif  // HPOSE_CORE_SEARCH_POSE_REFINER_H_
