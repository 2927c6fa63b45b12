#ifndef HPOSE_CORE_SEARCH_ESTIMATOR_H_
#define HPOSE_CORE_SEARCH_ESTIMATOR_H_

#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "core/common/status.h"
#include "core/depth/cluster_extractor.h"
#include "core/depth/depth_image.h"
#include "core/depth/depth_to_cloud.h"
#include "core/depth/floor_fitter.h"
#include "core/depth/intrinsics.h"
#include "core/depth/point_cloud.h"
#include "core/scoring/free_space.h"
#include "core/scoring/pose_lattice.h"
#include "core/scoring/pose_scorer.h"
#include "core/search/estimate.h"
#include "core/search/exact_search.h"
#include "core/search/pose_refiner.h"
#include "core/search/pose_search.h"
#include "core/search/template_models.h"
#include "core/search/view_comparison.h"
#include "core/templates/voxel_template.h"

namespace hpose {

class FloorTracker;
class RangeImage;
class TaskPool;

enum class SearchKind { kPaper, kExact };

const char* SearchKindName(SearchKind kind);
// Parses "paper" or "exact".
Result<SearchKind> ParseSearchKind(const std::string& name);

// What a pose's value is. kPaper: the paper's score, cluster voxels covered by the template.
// kFreeSpace: the same minus the template voxels that lie where the sensor saw through to
// something farther away (free space), which removes the paper score's blindness to a template
// that is larger than what was seen (clutter inside a template, side views taken for front
// views, a sparse far cluster swallowed anywhere inside the template).
enum class ScoreKind { kPaper, kFreeSpace };

const char* ScoreKindName(ScoreKind kind);
// Parses "paper" or "free-space".
Result<ScoreKind> ParseScoreKind(const std::string& name);

struct EstimatorOptions {
  DepthToCloudOptions cloud;
  FloorFitterOptions floor_fit;
  bool use_fixed_floor = false;  // true: `fixed_floor` instead of fitting every frame.
  FloorEstimate fixed_floor;
  ClusterOptions clusters;
  // The search's lattice. Its voxel edge (resolution_m) follows the templates unless
  // resolution_from_templates is false.
  PoseLattice lattice;
  // true: the search's voxel edge is the templates' own (the coarsest of them when they
  // differ), coarser still for a tall body (max_height_voxels); lattice.resolution_m is then
  // ignored (Estimator::options() holds the edge chosen). false: lattice.resolution_m as set.
  // Either way a template made at a finer edge than the search's is voxelised again at it from
  // its surface points (VoxeliseAgain), and one made at a coarser edge is refused. The
  // refinement fits every template's own surface, whatever edge it is searched at.
  bool resolution_from_templates = true;
  // A body taller than this many voxels of the templates' edge is searched on coarser voxels:
  // the tallest template's height / max_height_voxels, rounded up to a millimetre. A bound's
  // work grows with a template's columns (its surface over the edge squared), and columns of
  // more than 64 voxels are searched slab by slab: a 1.23 m humanoid made at 16 mm (83 voxels
  // with an arm raised) is searched at 28 mm in 0.50-0.65x the time, with headings and positions
  // as accurate, and found farther away (docs/BENCHMARKS.md). The shipped Nao templates
  // (40 voxels with an arm raised) and smaller bodies keep their edge. 0: never coarser than
  // the templates' own. Used with resolution_from_templates only.
  int max_height_voxels = 48;
  SearchKind search = SearchKind::kExact;
  ScorerKind scorer = ScorerKind::kFast;  // equal scores; kOctomapReference is slow.
  PaperSearchOptions paper;
  ExactSearchOptions exact;
  ScoreKind score = ScoreKind::kFreeSpace;
  FreeSpaceOptions free_space;
  // A pose's value is hit_weight * covered cluster voxels - free_space_weight * template voxels
  // in free space; the score is 100 * value / (hit_weight * cluster voxels).
  // 2 : 1 (a free voxel costs half a covered one) was best on the simulated protocol: weight
  // 1 : 1 loses side views, whose thin limbs leave some template voxels in free space
  // (docs/BENCHMARKS.md).
  int free_space_weight = 1;
  int hit_weight = 2;
  double range_image_focal_px = 300.0;  // bin size of the free-space range image.
  // The range image spans a depth image's rows from its top to its bottom (its edges from the
  // intrinsics), not only its readings' extent: where nothing returned a reading above the
  // tallest object (a level sensor in a room whose walls are beyond range, or none; a sensor
  // looking down on a floor that runs out of range), a template placed reaching higher is seen
  // through there (no return) instead of being out of view, unconfirmed and uncontradicted.
  // Its sides stay the readings': every column a sensor can measure sees the floor somewhere,
  // so columns without a single reading are ones it cannot (a Kinect's invalid band at the
  // image's side), not open space. false: the readings' extent alone (before). A frame given
  // as a cloud alone has no edges and keeps its readings' extent either way.
  bool range_image_spans_view = true;
  // ... but for a band of this share of the image's rows at its top and at its bottom: rows
  // there without a reading are taken for the sensor's invalid border, where its depth and
  // colour views do not overlap (PCL's recorded Kinect frames, registered to colour: the top 15
  // and the bottom 5 of 480 rows), not for open space. Within [0, 0.5).
  double range_image_edge_band = 0.05;
  // A cluster is the humanoid when its best score passes this. On simulated frames humanoids
  // score 60-77 at 1-2 m and clutter of similar height up to about 45 (docs/BENCHMARKS.md).
  double score_threshold = 50.0;
  // ... and, when its pose was refined, a refined fit (FitSummary::fit: the share of its points
  // on the template's surface times the share of the template's visible surface not seen
  // through) of at least this. Clutter that reaches the score threshold fits poorly where the
  // sensor sees through the template (simulated frames: humanoids 82-100, such clutter 26-53;
  // docs/BENCHMARKS.md). 0: the score alone decides (before).
  double min_humanoid_fit = 60.0;
  // ... and a refined pose must cover this share of the template's voxels, weighed by the
  // refined fit (0-1) to the eighth (HumanoidEvidenceShare, as far_min_evidence below). Clutter
  // that reaches the score and fit thresholds is mostly a box or a post inside the template's
  // outline, covering a small part of it: in random scenes (bench/cluster_choice_bench.cc, 4 800
  // scenes, 0.3-1.6 m high, -5 to 45 degrees down, 4-10 clutter objects) such clutter reached a
  // median of 0.008-0.013 and robots 0.24-0.25, their lowest 1% 0.03-0.05. With 0.01, clutter taken
  // for a humanoid in 327 scenes instead of 564, the robot found in 4 299 instead of 4 296
  // (docs/BENCHMARKS.md); as it weighs the fit to the eighth, a larger value would refuse robots
  // whose fit a noisier sensor lowers. A frame whose only passing cluster lacks it counts as one
  // where nothing passed (far_range_m). Not applied to the cluster the previous frame's humanoid
  // stood on (its hysteresis, tracked_score_threshold) once its track has shown
  // tracked_hold_min_evidence. 0: off (before).
  double min_humanoid_evidence = 0.01;
  // A track is exempt from min_humanoid_evidence on the cluster its humanoid stood on only once
  // one of its frames showed this much evidence (HumanoidEvidenceShare; FramePrior::
  // hold_confirmed): a robot followed out of view, behind an object or in a posture its
  // templates lack keeps being found as its evidence falls, while clutter taken for a humanoid in
  // one frame (evidence about min_humanoid_evidence) is not held in the frames where it lacks
  // it. Robots in simulated walks show 0.1-0.25 in every frame, clutter taken for a humanoid
  // 0.008-0.013 at the median and at most 0.05-0.15 (docs/BENCHMARKS.md). 0: every track is
  // exempt (before).
  double tracked_hold_min_evidence = 0.05;
  // Hysteresis for a tracked humanoid: the cluster the previous frame's humanoid stood on
  // (FramePrior, PoseTracker) is a humanoid from this score on when none of its templates
  // reaches score_threshold (the fit threshold still applies); every other cluster is held to
  // score_threshold. Kinect noise thickens a far cluster over more voxels than the template
  // covers, so a humanoid's score falls with distance (simulated, 0.9 m high and 20 degrees
  // down: a Nao 46-53 at 3-3.5 m, a 1.23 m humanoid 38-46 from 2.8 m; docs/BENCHMARKS.md): once
  // found near, it stays found walking away, while clutter elsewhere still needs the full
  // score. The held cluster's templates are searched down to score_threshold first and again
  // down to this only when none reaches it (straight down to this when the prior itself scored
  // below score_threshold), so frames whose humanoid passes are searched as without it. Used up
  // to score_threshold: at or above it, no hysteresis.
  double tracked_score_threshold = 35.0;
  // In a tracked stream, when templates fit the cluster the previous frame's humanoid stood on
  // equally well (within two standard errors) but the best fit's heading lies more than 90
  // degrees from the previous frame's while another's lies within 90 of it, that other
  // template's pose is taken (heading_from_prior): two templates that explain the same points
  // facing opposite ways is a front/back question the frame has not decided, as within one
  // template. false: the higher fit alone (before).
  bool prior_heading_across_templates = true;
  // In a tracked stream, a template's refined pose on the cluster the previous frame's humanoid
  // stood on that confirms that frame's heading has no runner-up heading searched for
  // (Candidate::heading_confirmed): it faces within this angle of the previous heading, passes
  // min_humanoid_fit, stopped inside its refinement basin, and the same place turned about fits
  // worse by more than heading_views.max_fit_sigmas standard errors (ConfirmsPreviousHeading).
  // On every walk measured a runner-up searched for there was decided against: every pose the
  // same, one heading flagged ambiguous in 1 280 frames no longer flagged.
  // The turned-about pose is evaluated once (about 0.15 ms); the runner-up's search and
  // refinement it saves took about 0.9 ms of a tracked walk's frame (docs/BENCHMARKS.md). A robot
  // turned about between frames is still seen turned at once: where the optimum faces its old
  // way, the turned-about pose (its true heading) fits as well. The optimum is the same either
  // way. 0: every runner-up searched, tracked frames' candidates equal to cold frames' (before).
  double tracked_heading_confirm_rad = 15.0 * kPi / 180.0;
  // In a tracked stream, on the cluster the previous frame's humanoid stood on, a template other
  // than that frame's is refined only when its search score comes within this many points of
  // the previous frame's template's score there, or when that template's refined pose does not
  // pass as a humanoid; otherwise its candidate keeps its search pose (Candidate::refined false,
  // no runner-up searched) and the detection keeps the previous frame's template. Which template
  // a frame fits best shows in the search scores first: on the frame benchmark's protocols
  // (three bodies, five mounts and bodies, 540 frames, 458 clusters with both templates refined)
  // the template with the best refined fit never scored more than 1.1 points below the other
  // (docs/BENCHMARKS.md, "Other templates of a tracked humanoid"), and a robot that changes posture
  // raises the other template's score above the previous one's. Negative: every template refined,
  // as in a cold frame (before).
  double tracked_other_template_margin = 3.0;
  // ... and its search waits for that template's and stops once it has proved that no pose comes
  // within tracked_other_template_margin of that template's score (Candidate::
  // stopped_below_threshold, its score_upper_bound below that), so that its optimum is not
  // proved where it would not be refined; where the previous frame's template then fails to
  // pass, the search goes on down to the score threshold and the template is refined. The
  // detection is the same either way. False: the search proves its optimum (before).
  bool tracked_other_template_stops = true;
  // A far cluster, cold: Kinect noise lowers a humanoid's score there too (above), and a cold
  // frame has no prior to hold it by. A cluster whose centroid lies at least far_range_m from
  // the sensor's optical centre is searched down to far_score_ratio * score_threshold, and passes
  // below score_threshold only on strong refined evidence: the share of the template's voxels
  // its pose covers times the refined fit (0-1) to the eighth (HumanoidEvidenceShare) at least
  // far_min_evidence. Clutter scores as much far away as near, but covers less of the template or
  // fits it worse (random scenes of bench/cluster_choice_bench.cc: far robots scoring 40-50
  // reach a median of 0.18-0.21, such clutter at most 0.054; docs/BENCHMARKS.md). The fit
  // threshold still applies; the held cluster of a tracked stream keeps its own threshold.
  // far_score_ratio = 1 (or far_range_m = infinity): every cluster held to score_threshold.
  double far_range_m = 2.5;
  double far_score_ratio = 0.8;
  double far_min_evidence = 0.08;
  // A cluster whose centroid lies nearer than this to the sensor's optical centre (metres) is
  // searched on the voxels that two or more of its points fall in. That near, a Kinect puts
  // tens of points in each voxel of a surface (some 13 in a 16 mm voxel's face at 2.5 m, more
  // nearer), and a voxel with a single point is mostly a stray one off the surface, which every
  // pose leaves unexplained and which flattens the search's bounds. At 2.5 m: the tracked walk
  // in 0.89-0.91x the time (0.79x the bounds) and the scattered frames' p99 in 0.84-0.88x, with
  // the same headings and positions on the accuracy benchmark, but in random scenes clutter
  // taken for a humanoid in 7 more of 2 400 and 7 fewer first detections within 10 degrees of
  // the robot's heading (docs/BENCHMARKS.md, "Lone points' voxels"): an option for a CPU where
  // time is short, off by default. Farther clusters keep every voxel with a point (a voxel's face
  // gets fewer points there, and depth noise spreads them over more voxels). 0: off.
  double two_points_a_voxel_within_m = 0.0;
  // true: the exact search stops proving a cluster below the threshold as soon as it has (its
  // candidate then carries the best pose it evaluated and the bound, stopped_below_threshold).
  // false: every candidate's exact
  // optimum is computed, however low (slower on clutter).
  bool stop_below_threshold = true;
  // Make at construction every search table the exact search otherwise makes on first use
  // (per shipped template about 40 ms on one core, spread over `threads`, and about 27 MB), and
  // write the memory of the searches' queues (ExactSearch::ReserveQueues, about 10 MB), so
  // that the first frames take no longer than the later ones, nor a frame whose searches are
  // the largest yet (a page's first touch costs microseconds): for estimators that serve a
  // stream of frames (the daemon's). One-off estimates are quicker without (they make only
  // what they use).
  bool make_tables_at_start = false;
  // When nothing in a frame passes as a humanoid, its clusters are searched again with the
  // templates standing one voxel lower and one higher than the floor, then two, ... up to this
  // many; of the first offsets at which something passes, the one whose humanoid fits best
  // gives the detections (Candidate::height_offset_m). A search finds a body within about a
  // centimetre of its template's height: a robot with its knees bent stands lower than a
  // template made with straight legs, one on a mat or thick soles higher, and a floor fit may
  // be off by as much. Frames whose humanoid passes on the floor are searched once, as without
  // it; a tracked stream's frames start at the offset the previous frame's humanoid stood at.
  // 0: only on the floor (before).
  int height_offset_voxels = 2;
  // ... where a cluster passes (unless it is the one the previous frame's humanoid stood on)
  // only if the search's pose covers this share of the template's voxels with cluster voxels
  // (Candidate::hits / template_voxels). Clutter that passes the other thresholds off the floor
  // is a box or post inside the template's outline again: in random scenes without a robot it
  // covered at most 0.13, robots that stood a voxel lower or higher than their templates 0.2-0.4
  // seen whole (docs/BENCHMARKS.md). Their fits are lower than on the floor (the template and
  // the body differ), which weighs down HumanoidEvidenceShare's fit to the eighth: the share of
  // the template alone tells them apart.
  double height_offset_min_coverage = 0.15;
  // ... and only the clusters whose height lies within this fraction of the template's as moved
  // (max_height_ratio_error, tighter) are searched there. Without it a frame without a humanoid
  // has every cluster searched again at each offset; with it only those about a template's
  // height (six simulated robot-less frames, one voxel of offset: p90 144 -> 94 ms on one core,
  // docs/BENCHMARKS.md).
  double height_offset_height_error = 0.1;
  // A cluster is searched with a template only when its height is within this fraction of the
  // height the template would show there (0.25: 0.75x to 1.25x): the template's height, or,
  // where the top of the image cuts the view lower (a level sensor near the floor sees a 58 cm
  // robot only up to ~0.75 m at 1 m), the highest point the sensor sees above the cluster: along
  // the depth image's top row (its intrinsics), or for a cloud alone its highest point's ray
  // (where nothing above returned a reading, that ends lower than the image and lets shorter
  // clusters through). Occlusion from below keeps a cluster's top. Negative disables the check.
  double max_height_ratio_error = 0.25;
  // false: compare with the template's full height even where the view ends lower (the
  // previous behaviour, which skipped raised arms cut off by the image top).
  bool height_check_uses_view = true;
  // Optional checks on the cluster's apparent width (its extent across the line of sight)
  // against [min_width_ratio x the template's narrowest silhouette, max_width_ratio x its
  // widest]. Off by default (negative): they are heuristics that skipped side-on robots; the
  // free-space evidence and the bound below decide instead.
  double min_width_ratio = -1.0;
  double max_width_ratio = -1.0;
  // Continuous refinement of each candidate's lattice pose and the refined evidence that
  // chooses between the runner-up heading and between templates (pose_refiner.h).
  RefineOptions refine;
  // How the depth images decide between a refined heading and its refined runner-up (front /
  // back): view_comparison.h. Asked only when either heading's refined fit reaches
  // min_humanoid_fit: for clutter that fails the fit either way, the higher fit is reported.
  ViewComparisonOptions heading_views;
  // Threads for the (cluster, template) searches and refinements of a frame, the calling
  // thread included; 0: one per core. Results do not depend on it.
  int threads = 1;
};

// Default options (the paper's settings, Kinect v1) in one place.
EstimatorOptions DefaultEstimatorOptions();

// The voxel edge a body `height_m` tall, made at `resolution_m`, is searched at: its own, or
// for a body taller than `max_height_voxels` (> 0) of them its height / max_height_voxels,
// rounded up to a millimetre (EstimatorOptions::max_height_voxels).
double TallBodySearchEdge(double height_m, double resolution_m, int max_height_voxels);

// What a stream's earlier frames tell the next one (PoseTracker keeps it): the pose of the
// humanoid found in the previous frame (ground frame), and the stream's floor tracker, which
// keeps the floor while it still fits instead of fitting it every frame.
struct FramePrior {
  bool has_pose = false;
  std::string template_name;
  Pose2D pose;
  // Its search score: below score_threshold (it passed by tracked_score_threshold), the cluster
  // it stands on is searched straight down to tracked_score_threshold.
  double score = 100.0;
  // How far above the floor its template stood (Candidate::height_offset_m): the frame's
  // searches start there.
  double height_offset_m = 0.0;
  // Its track has shown EstimatorOptions::tracked_hold_min_evidence in some frame (or the pose
  // is one given, as an initial pose): the cluster it stands on is exempt from
  // min_humanoid_evidence. False: held to it like any other cluster.
  bool hold_confirmed = true;
  // When nothing passes at height_offset_m, the templates are tried off the floor
  // (EstimatorOptions::height_offset_voxels) at every offset in their order (one voxel lower,
  // one higher, two lower, two higher, ...) while this is negative; else at the one offset of
  // that order this indexes (modulo their number), as a stream that has lost its robot tries
  // them, one a frame (PoseTracker).
  int height_offset_turn = -1;
  FloorTracker* floor = nullptr;  // optional; ignored with a fixed floor.
};

// Where a depth image's view ends, as slopes of rays in the sensor frame (x / z, y / z) through
// its outermost pixel centres, and one pixel's slope; NaN for a frame given as a cloud alone,
// whose points' own extent (RangeImage) stands in for them.
struct ImageEdges {
  double left_tan = std::numeric_limits<double>::quiet_NaN();
  double right_tan = std::numeric_limits<double>::quiet_NaN();
  double top_tan = std::numeric_limits<double>::quiet_NaN();
  double bottom_tan = std::numeric_limits<double>::quiet_NaN();
  double pixel_tan = std::numeric_limits<double>::quiet_NaN();
};

// The depth-template estimator: cloud -> floor -> clusters -> search every template on every
// cluster. Thread-compatible: one Estimate call at a time per instance.
class Estimator {
 public:
  // Fails (kInvalidArgument) without templates, with duplicate names, with a template made at
  // a coarser voxel edge than the lattice's (resolution_from_templates false), or with invalid
  // options.
  // With `shared` (another estimator's models(), made from the same templates), a template's
  // models are taken from there instead of made again where they were made alike (same name and
  // voxel count, lattice and surface spacing): estimators of one process then hold one copy of
  // each template's rotations, search tables and surface, made once.
  static Result<std::unique_ptr<Estimator>> Create(EstimatorOptions options,
                                                   std::vector<VoxelTemplate> templates,
                                                   const std::vector<TemplateModels>& shared = {});

  // Fails with kInvalidArgument (bad intrinsics, size mismatch, no valid depth) or
  // kFailedPrecondition (no floor found). "No humanoid" is not a failure: see
  // Estimate::Humanoids().
  // With `prior`, the cluster holding the prior pose is searched from it first (same optimum,
  // see TrackingInfo), where its heading is ambiguous the one nearer the prior's is given
  // (Candidate::heading_from_prior), and where the frame confirms the prior's heading no
  // runner-up is searched for (Candidate::heading_confirmed).
  Result<Estimate> EstimateDepth(const DepthImage& depth, const Intrinsics& intrinsics,
                                 const FramePrior* prior = nullptr) const;
  // `cloud_sensor` in the sensor frame (x right, y down, z forward), metres; NaNs are skipped.
  Result<Estimate> EstimateCloud(const PointCloud& cloud_sensor,
                                 const FramePrior* prior = nullptr) const;

  const std::vector<VoxelTemplate>& templates() const { return templates_; }
  const EstimatorOptions& options() const { return options_; }
  // Each template's models (same order as templates()), for Create's `shared`.
  std::vector<TemplateModels> models() const;

  ~Estimator();

 private:
  Estimator(EstimatorOptions options, std::vector<VoxelTemplate> templates,
            std::vector<VoxelTemplate> searched, const std::vector<TemplateModels>& shared);
  // `edges`: the depth image's where the frame came as an image with intrinsics.
  Result<Estimate> Run(const PointCloud& cloud_sensor, double cloud_ms, const FramePrior* prior,
                       const ImageEdges& edges) const;
  // Every (cluster, template) search of a frame and its refinement, with the templates standing
  // `height_offset_m` above the floor, and the detections: fills `out`'s candidates,
  // detections, clusters' searched flags, tracking.tracked and timings.refine_ms from its floor
  // and cluster summaries. `on_floor`: the frame's clusters (ground frame); `range`: its range
  // image (empty when neither the free space nor the refinement reads it); `edges` as for Run.
  void SearchClusters(const std::vector<Cluster>& on_floor, const RangeImage& range,
                      const ImageEdges& edges, const FramePrior* prior, double height_offset_m,
                      Estimate* out) const;

  EstimatorOptions options_;
  std::vector<VoxelTemplate> templates_;
  // The same templates at the search's voxel edge (voxelised again where theirs is finer).
  std::vector<VoxelTemplate> searched_;
  std::vector<std::shared_ptr<const TemplateRotations>> rotations_;  // one per template.
  // Narrowest and widest horizontal silhouette of each template over all headings (metres),
  // counting voxels above the clusters' floor band only.
  std::vector<std::pair<double, double>> silhouette_widths_;
  // One per template, for refinement.
  std::vector<std::shared_ptr<const SurfaceModel>> surfaces_;
  std::unique_ptr<PoseSearch> search_;
  std::unique_ptr<TaskPool> pool_;
  // The free space a cluster's searches read, per z cell from 0 up to the highest template
  // cell: within free_grow_[z] cells of the box of its cells (FreeSpaceGrow, the largest over
  // the templates).
  std::vector<int> free_grow_;
};

}  // namespace hpose

#endif  // HPOSE_CORE_SEARCH_ESTIMATOR_H_
