#ifndef HPOSE_CORE_SEARCH_ESTIMATE_H_
#define HPOSE_CORE_SEARCH_ESTIMATE_H_

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/common/pose2d.h"
#include "core/depth/floor_estimate.h"
#include "core/search/humanoid_view.h"

namespace hpose {

// The refined, noise-aware evidence of a pose (PoseEvidence of pose_refiner.h, summarised).
struct FitSummary {
  double fit = 0.0;           // 100 * explained * (1 - contradicted).
  double explained = 0.0;     // fraction of the cluster's points on the template surface.
  double contradicted = 0.0;  // fraction of the template's visible surface seen through.
  double fit_sigma = 0.0;     // standard error of `fit` from the counts behind it.
  double cost = 0.0;  // robust negative log-likelihood (nats); lower is better (PoseEvidence).
  // Share of the template's surface facing the sensor that lies within the view (the range
  // image's: the depth image's rows and its readings' columns, or a cloud's readings' span;
  // EstimatorOptions::range_image_spans_view): 1 for all of it, less where the image's edges
  // cut the template.
  double in_view = 1.0;
};

// One template's best match on one cluster.
struct Candidate {
  std::string template_name;
  int cluster_index = -1;
  // Robot frame in the ground frame: the refined pose when `refined`, else the lattice pose.
  Pose2D pose;
  Pose2D lattice_pose;  // the search's optimum on the (x, y, theta) lattice.
  // How far above the fitted floor the template stood (metres, a whole number of the search's
  // voxels; EstimatorOptions::height_offset_voxels): 0 unless nothing passed on the floor.
  double height_offset_m = 0.0;
  bool refined = false;  // `pose` comes from the continuous refinement of lattice_pose.
  // The frame contradicted the template's free limbs where the whole template fitted, more than
  // the rest of it (RefineOptions::refit_without_moved_limbs): the robot holds its arms
  // otherwise. The candidate each cluster's detection takes is then fitted again without them.
  bool free_limbs_moved = false;
  // `pose` was fitted without the template's free limbs (free_limbs_moved; `fit` stays the
  // whole template's where it fitted first).
  bool free_limbs_left_out = false;
  // Covariance of the refined (x, y, theta) (m^2, rad^2); zero when not refined.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  FitSummary fit;           // evidence at `pose`.
  double score = 0.0;       // what the search maximised, 100 * value / cluster voxels (<= 100).
  double coverage = 0.0;    // the paper's score: 100 * cluster voxels covered / cluster voxels.
  int free_space_hits = 0;  // template voxels in observed free space at the pose.
  // True when the search stopped once it had proved that no pose reaches the threshold (the
  // score threshold; in a tracked frame, for a template other than the previous frame's on
  // its cluster, that template's score less EstimatorOptions::tracked_other_template_margin):
  // `pose` and `score` are then the best pose it evaluated and its exact score (a real pose,
  // not proven the optimum), `score_upper_bound` bounds every pose's score, and there is no
  // runner-up.
  bool stopped_below_threshold = false;
  double score_upper_bound = 0.0;
  int hits = 0;
  int cluster_voxels = 0;
  int template_voxels = 0;  // voxels of the template as searched (its lattice's voxel edge).
  // The best pose with theta more than 30 deg away; not searched for when the template's refined
  // fit is far behind another's on the cluster (RefineOptions::runner_up_fit_sigmas,
  // search_far_behind_runner_up), and none when every such pose scores more than
  // RefineOptions::runner_up_score_window below `score` (runner_up_within_score_window; the
  // runner_up_score then bounds theirs).
  bool has_runner_up = false;
  // Refined like `pose`, unless it is far behind in score (RefineOptions::
  // runner_up_score_window, when it is searched that far) or its template far behind in fit:
  // then where the search left it.
  Pose2D runner_up_pose;
  double runner_up_score = 0.0;
  double refine_ms = 0.0;  // what refining `pose` and the runner-up took (wall time).
  FitSummary runner_up_fit;
  // The runner-up's refined evidence is as good as the pose's within noise: the heading is
  // ambiguous (typically front/back at distance); both poses are reported.
  bool heading_ambiguous = false;
  // The depth images' verdict between `pose` and the runner-up (view_comparison.h): their
  // log-likelihood ratio (nats, positive favours `pose`) and its standard error; zero when not
  // compared.
  double heading_log_likelihood_ratio = 0.0;
  double heading_log_likelihood_sigma = 0.0;
  // The heading was ambiguous and the pose given is the one nearer the previous frame's heading
  // (a tracked stream, FramePrior): continuity decided what this frame alone could not.
  bool heading_from_prior = false;
  // A tracked frame: the pose confirmed the previous frame's heading (facing within
  // EstimatorOptions::tracked_heading_confirm_rad of it, its turned-about pose fitting far
  // worse), so no runner-up heading was searched for (has_runner_up false).
  bool heading_confirmed = false;
  std::int64_t poses_evaluated = 0;   // exact score evaluations.
  std::int64_t bounds_evaluated = 0;  // branch-and-bound upper bounds (exact search only).
};

// Which rule refused a cluster's best candidate as the humanoid: the first it failed, in this
// order (EstimatorOptions names each threshold).
enum class Refusal {
  kNone,              // not refused: the humanoid.
  kScore,             // the search score stayed below the cluster's threshold.
  kFit,               // refined, its fit is below min_humanoid_fit.
  kEvidence,          // ... its evidence (HumanoidEvidenceShare) below min_humanoid_evidence.
  kFarEvidence,       // a far cluster passing only the far score, without far_min_evidence.
  kOffFloorCoverage,  // templates off the floor: it covers less than height_offset_min_coverage.
};

// In which points Detection::template_margin is.
enum class MarginKind {
  // Search score points: the best's score less the second template's (refinement off, or a
  // tracked frame left the second unrefined: EstimatorOptions::tracked_other_template_margin).
  kScore,
  kFit,  // fit points: both templates refined, the best's fit less the second's.
  // Score points, at least: the second's search stopped (Candidate::stopped_below_threshold);
  // the best's score less the second's score_upper_bound.
  kScoreAtLeast,
};

// A cluster's verdict: its best template, and how far ahead of the next template it is.
// The template is chosen by the refined evidence (highest Candidate::fit.fit) of each
// template's pose.
struct Detection {
  Candidate best;
  std::string second_template;  // empty with one template.
  // How far ahead of the second template it is, in the points template_margin_kind names;
  // with one template, its score.
  double template_margin = 0.0;
  MarginKind template_margin_kind = MarginKind::kScore;
  // The margin is within what noise explains (two standard errors of the fits).
  bool template_ambiguous = false;
  bool is_humanoid = false;  // not refused (the estimator sets both).
  Refusal refused_by = Refusal::kNone;
  // The score threshold this cluster was held to: EstimatorOptions::tracked_score_threshold on
  // the cluster the previous frame's humanoid stood on, else score_threshold.
  double score_threshold = 0.0;
};

struct ClusterSummary {
  int index = 0;
  int points = 0;
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();  // ground frame, metres.
  Eigen::Vector3f min = Eigen::Vector3f::Zero();
  Eigen::Vector3f max = Eigen::Vector3f::Zero();
  bool searched = false;  // false when its size ruled out every template.
};

struct StageTimings {
  double cloud_ms = 0.0;
  double floor_ms = 0.0;
  double cluster_ms = 0.0;
  double search_ms = 0.0;  // lattice search and refinement together.
  double refine_ms = 0.0;  // of which the refinement.
  double total_ms = 0.0;
};

// Everything one frame produced.
// How a frame was searched: cold, or seeded with the previous frame's pose (PoseTracker). The
// optimum is the same either way: a seeded search still proves the global optimum, so a robot
// that moved far (or a second one) is found in the same frame. Only a pose that confirms the
// previous heading has no runner-up searched for (Candidate::heading_confirmed).
struct TrackingInfo {
  bool tracked = false;       // the previous pose seeded the search of the cluster holding it.
  bool prior_given = false;   // a previous pose was offered (false: a cold start).
  bool floor_reused = false;  // the previous frame's floor still fitted this frame's points.
  std::string prior_template;
  Pose2D prior_pose;  // ground frame.
  // The cluster the previous frame's humanoid stood on (Estimate::clusters' index), -1 if none.
  int held_cluster = -1;
};

struct Estimate {
  FloorEstimate floor;
  int cloud_points = 0;
  std::vector<ClusterSummary> clusters;
  std::vector<Candidate> candidates;  // every (cluster, template), best score first.
  // One per searched cluster: the humanoids (is_humanoid) first, the one with the most evidence
  // first (DetectionBefore), then the others by score.
  std::vector<Detection> detections;
  StageTimings timings;
  TrackingInfo tracking;
  // How many times the clusters were searched: 1, or more when nothing passed with the templates
  // on the floor (or where the previous frame's humanoid stood) and they were searched again
  // lower and higher (EstimatorOptions::height_offset_voxels).
  int height_passes = 1;

  // The detections that pass the thresholds (is_humanoid), in the order of `detections`, read
  // in place: the view and references to its detections are valid while this Estimate lives
  // and `detections` is not resized. Not offered on a temporary Estimate, whose detections
  // would be gone before the view is read.
  HumanoidView Humanoids() const& { return HumanoidView(detections); }
  HumanoidView Humanoids() const&& = delete;
};

}  // namespace hpose

#endif  // HPOSE_CORE_SEARCH_ESTIMATE_H_
