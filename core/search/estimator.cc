#include "core/search/estimator.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <utility>

#include "core/common/task_pool.h"
#include "core/depth/cloud_validation.h"
#include "core/depth/floor_tracker.h"
#include "core/search/detection_order.h"
#include "core/search/exact_search.h"
#include "core/search/fit_summary.h"
#include "core/search/free_space_grow.h"
#include "core/search/heading_confirmation.h"
#include "core/search/prepared_cluster.h"
#include "core/search/view_comparison.h"

namespace hpose {
namespace {

using Clock = std::chrono::steady_clock;

double MsSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

std::unique_ptr<PoseSearch> MakeSearch(const EstimatorOptions& options) {
  switch (options.search) {
    case SearchKind::kPaper:
      return std::make_unique<PaperSearch>(options.paper);
    case SearchKind::kExact:
      return std::make_unique<ExactSearch>(options.exact);
  }
  return nullptr;
}

// The template's narrowest and widest extent across a line of sight, over headings every 5
// degrees, for voxels above `min_z` (what clustering keeps), voxel size included.
std::pair<double, double> SilhouetteWidths(const VoxelTemplate& tpl, double min_z) {
  double narrow = 1e9, wide = 0.0;
  for (int deg = 0; deg < 180; deg += 5) {
    const double c = std::cos(DegToRad(deg)), s = std::sin(DegToRad(deg));
    double lo = 1e9, hi = -1e9;
    for (const Eigen::Vector3f& v : tpl.voxels) {
      if (v.z() + 0.5 * tpl.resolution_m < min_z) continue;
      const double w = -s * v.x() + c * v.y();
      lo = std::min(lo, w);
      hi = std::max(hi, w);
    }
    if (hi < lo) continue;
    narrow = std::min(narrow, hi - lo + tpl.resolution_m);
    wide = std::max(wide, hi - lo + tpl.resolution_m);
  }
  return {narrow > wide ? 0.0 : narrow, wide};
}

// Where the top of the sensor's view is: the ray through the top row of the image (its middle
// column), as a slope in the ground frame. A cluster whose top would lie above that ray is cut
// by the image border. The image is the depth image where the frame came as one (its
// intrinsics), else the cloud's own extent (RangeImage), which ends at the highest point seen:
// below the image's top where nothing above returned a reading (open space, beyond range).
struct TopOfView {
  bool known = false;
  double sensor_height_m = 0.0;
  double slope = 0.0;  // rise per metre of horizontal distance.

  // The highest point the sensor sees above the cluster (at its nearest horizontal distance);
  // +inf when unknown.
  double HeightAbove(const Cluster& c) const {
    if (!known) return std::numeric_limits<double>::infinity();
    double nearest = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3f& p : c.points) {
      nearest = std::min(nearest, static_cast<double>(p.head<2>().norm()));
    }
    if (!std::isfinite(nearest)) return std::numeric_limits<double>::infinity();
    return sensor_height_m + nearest * slope;
  }
};

TopOfView TopOfViewOf(const RangeImage& range, const ImageEdges& edges,
                      const FloorEstimate& floor) {
  TopOfView v;
  double top_tan = range.height() > 0 ? range.TopTan() : std::nan("");
  if (std::isfinite(edges.top_tan)) {  // the image's top, above any point it holds.
    top_tan = std::isfinite(top_tan) ? std::min(top_tan, edges.top_tan) : edges.top_tan;
  }
  if (!std::isfinite(top_tan)) return v;
  const Eigen::Vector3d dir =
      floor.ground_from_sensor.linear() * Eigen::Vector3d(0.0, top_tan, 1.0);
  const double horizontal = dir.head<2>().norm();
  if (!(horizontal > 1e-6)) return v;
  v.known = true;
  v.sensor_height_m = floor.ground_from_sensor.translation().z();
  v.slope = dir.z() / horizontal;
  return v;
}

// The image's left and right edges (slopes x / z) and how near to them a point counts as cut:
// the depth image's, else the range image's extent; `known` false without either.
struct SideEdges {
  bool known = false;
  double left_tan = 0.0, right_tan = 0.0, near_tan = 0.0;
  Eigen::Isometry3d sensor_from_ground = Eigen::Isometry3d::Identity();

  // Whether a point of `c` (ground frame) lies within near_tan of the left or right edge: the
  // image cuts the cluster there, and what shows of it may not reach its top (a robot at the
  // image's side shows an arm or a shoulder, not its head).
  bool Cuts(const Cluster& c) const {
    if (!known) return false;
    for (const Eigen::Vector3f& p : c.points) {
      const Eigen::Vector3d s = sensor_from_ground * p.cast<double>();
      if (!(s.z() > 1e-3)) continue;
      const double t = s.x() / s.z();
      if (t <= left_tan + near_tan || t >= right_tan - near_tan) return true;
    }
    return false;
  }
};

// The share of the height a template shows that a cluster the image's side cuts must reach.
constexpr double kSideCutShare = 0.5;

SideEdges SideEdgesOf(const RangeImage& range, const ImageEdges& edges,
                      const FloorEstimate& floor) {
  SideEdges e;
  constexpr double kNearPixels = 3.0;
  if (std::isfinite(edges.left_tan) && std::isfinite(edges.right_tan) &&
      std::isfinite(edges.pixel_tan)) {
    e.known = true;
    e.left_tan = edges.left_tan;
    e.right_tan = edges.right_tan;
    e.near_tan = kNearPixels * edges.pixel_tan;
  } else if (range.width() > 0) {
    e.known = true;
    e.left_tan = -range.u0() / range.focal();
    e.right_tan = (range.width() - range.u0()) / range.focal();
    e.near_tan = kNearPixels / range.focal();
  }
  e.sensor_from_ground = floor.ground_from_sensor.inverse();
  return e;
}

// Refines the candidate's pose (the search's optimum); RefineRunnerUp then decides its heading.
void RefineBest(const SurfaceModel& model, const Observation& obs, const RefineOptions& o,
                Candidate* cand) {
  const RefinedPose best = RefinePose(model, obs, cand->lattice_pose, o);
  cand->pose = best.pose;
  cand->refined = true;
  cand->covariance = best.covariance;
  cand->free_limbs_moved = best.free_limbs_moved;
  cand->fit = Summarise(best.evidence);
}

// Whether a candidate's fit is within `sigmas` standard errors of the best fit of its cluster
// (always with sigmas <= 0).
bool Contends(const FitSummary& fit, const FitSummary& leader, double sigmas) {
  if (!(sigmas > 0.0)) return true;
  return leader.fit - fit.fit <= sigmas * std::hypot(leader.fit_sigma, fit.fit_sigma);
}

// Refines the runner-up of a candidate refined by RefineBest (the best heading more than 30
// degrees away) and chooses between them. With the view comparison on and a runner-up close
// enough in search score to be refined too, the depth images decide (CompareViews) when their
// likelihood ratio is decisive, and the heading is ambiguous when it is not (the pose is then the
// one the ratio leans to, or with undecided_follow_ratio off the one with the higher refined
// fit). Otherwise, and when neither refined fit reaches `humanoid_fit` (the cluster is no
// humanoid whichever heading it is given, so the depth images are not asked), the higher
// refined fit wins and the heading is ambiguous when the fits are within two standard errors of
// each other. A candidate that does not `contend` (its template's fit is far behind another
// template's on the cluster) has its runner-up only evaluated where it lies, like a runner-up
// far behind in score. An ambiguous heading with `prior_theta` (the previous frame's heading,
// when it stood on this cluster) is the one nearer to it; with it, fits far apart facing its way
// decide without the depth images (ViewComparisonOptions::max_fit_sigmas). `rescore` recomputes the
// search's counts at the lattice pose of a runner-up that wins.
template <typename Rescore>
void RefineRunnerUp(const SurfaceModel& model, const Observation& obs, const RefineOptions& o,
                    const ViewComparisonOptions& views, double humanoid_fit,
                    const double* prior_theta, bool contend, const Rescore& rescore,
                    Candidate* cand) {
  if (!cand->has_runner_up) return;
  const Pose2D other_lattice = cand->runner_up_pose;
  RefinedPose other;
  const bool close = contend && cand->runner_up_score >= cand->score - o.runner_up_score_window;
  if (close) {
    other = RefinePose(model, obs, other_lattice, o);
  } else {
    other.pose = other_lattice;
    other.evidence = EvaluatePose(model, obs, other_lattice, o);
  }
  FitSummary other_fit = Summarise(other.evidence);
  bool take_other = other_fit.fit > cand->fit.fit;
  bool ambiguous = WithinNoise(cand->fit, other_fit);
  ViewComparison cmp;
  // In a tracked stream the fits decide alone (ViewComparisonOptions::max_fit_sigmas) when the
  // better one (take_other so far) faces the previous frame's way, both pass as a humanoid and
  // they are far apart.
  const bool fits_decide = views.max_fit_sigmas > 0.0 && prior_theta != nullptr &&
                           std::abs(AngleDiff(take_other ? other.pose.theta : cand->pose.theta,
                                              *prior_theta)) <= 0.5 * kPi &&
                           std::min(cand->fit.fit, other_fit.fit) >= humanoid_fit &&
                           (take_other ? FarAhead(other_fit, cand->fit, views.max_fit_sigmas)
                                       : FarAhead(cand->fit, other_fit, views.max_fit_sigmas));
  if (views.enabled && close && !fits_decide &&
      std::max(cand->fit.fit, other_fit.fit) >= humanoid_fit) {
    cmp = CompareViews(model, obs, cand->pose, other.pose, o, views);
    const bool decisive =
        cmp.sigma > 0.0 && std::abs(cmp.log_likelihood_ratio) >= views.decisive_sigmas * cmp.sigma;
    if (decisive || (views.undecided_follow_ratio && cmp.sigma > 0.0)) {
      take_other = cmp.log_likelihood_ratio < 0.0;
    }
    ambiguous = !decisive;
  }
  if (ambiguous && prior_theta != nullptr) {
    take_other = std::abs(AngleDiff(other.pose.theta, *prior_theta)) <
                 std::abs(AngleDiff(cand->pose.theta, *prior_theta));
    cand->heading_from_prior = true;
  }
  if (take_other) {
    cand->runner_up_pose = cand->pose;
    cand->runner_up_fit = cand->fit;
    std::swap(cand->score, cand->runner_up_score);
    cand->pose = other.pose;
    cand->lattice_pose = other_lattice;
    cand->covariance = other.covariance;
    cand->free_limbs_moved = other.free_limbs_moved;
    cand->fit = other_fit;
    cmp.log_likelihood_ratio = -cmp.log_likelihood_ratio;
    rescore(cand);
  } else {
    cand->runner_up_pose = other.pose;
    cand->runner_up_fit = other_fit;
  }
  cand->heading_ambiguous = ambiguous;
  cand->heading_log_likelihood_ratio = cmp.log_likelihood_ratio;
  cand->heading_log_likelihood_sigma = cmp.sigma;
}

// EstimatorOptions::prior_heading_across_templates: the candidate among those whose fit is
// within noise of the best (cands[0], sorted) to put first when the best faces away from
// `prior_theta` (more than 90 degrees) and another faces within 90 degrees of it (the nearest
// such; not one that misses `min_fit` where the best reaches it); 0 (the best) otherwise.
size_t PriorHeadingChoice(const std::vector<const Candidate*>& cands, double prior_theta,
                          double min_fit) {
  const Candidate& best = *cands.front();
  if (!best.refined || std::abs(AngleDiff(best.pose.theta, prior_theta)) <= 0.5 * kPi) return 0;
  size_t chosen = 0;
  double nearest = 0.5 * kPi;
  for (size_t k = 1; k < cands.size(); ++k) {
    const Candidate& c = *cands[k];
    if (c.stopped_below_threshold || !c.refined || !WithinNoise(best.fit, c.fit) ||
        c.fit.fit < std::min(best.fit.fit, min_fit)) {
      continue;
    }
    const double off = std::abs(AngleDiff(c.pose.theta, prior_theta));
    if (off < nearest) {
      nearest = off;
      chosen = k;
    }
  }
  return chosen;
}

// The candidate of `candidates` on the same cluster with the same template as `c`, or null.
Candidate* CandidateOf(std::vector<Candidate>* candidates, const Candidate& c) {
  for (Candidate& other : *candidates) {
    if (other.cluster_index == c.cluster_index && other.template_name == c.template_name) {
      return &other;
    }
  }
  return nullptr;
}

// Whether a candidate passes as a humanoid, and if not the first rule it fails: its search must
// reach `threshold`, and when refined its fit min_humanoid_fit and, unless `evidence_exempt`
// (the held cluster of a confirmed track: FramePrior::hold_confirmed), its evidence
// min_humanoid_evidence.
Refusal HumanoidRefusal(const Candidate& c, double threshold, bool evidence_exempt,
                        const EstimatorOptions& o) {
  if (c.stopped_below_threshold || !(c.score >= threshold)) return Refusal::kScore;
  if (!c.refined) return Refusal::kNone;
  if (!(c.fit.fit >= o.min_humanoid_fit)) return Refusal::kFit;
  if (!evidence_exempt && !(HumanoidEvidenceShare(c) >= o.min_humanoid_evidence)) {
    return Refusal::kEvidence;
  }
  return Refusal::kNone;
}

bool PassesAsHumanoid(const Candidate& c, double threshold, bool evidence_exempt,
                      const EstimatorOptions& o) {
  return HumanoidRefusal(c, threshold, evidence_exempt, o) == Refusal::kNone;
}

// One detection per cluster: among its templates with a pose, the one whose pose the refined
// evidence supports best (highest fit; the search score when not refined), or in a tracked
// stream the one PriorHeadingChoice takes (`prior_theta`: the previous frame's heading on the
// cluster it stood on); in the order of DetectionBefore. `held_cluster`: the cluster the
// previous frame's humanoid stood on, or -1. `off_floor`: the templates stood off the floor
// (EstimatorOptions::height_offset_voxels), where every cluster but the held one must also cover
// height_offset_min_coverage of its template. `evidence_exempt_cluster`: the held cluster when
// its track is confirmed (FramePrior::hold_confirmed), else -1.
std::vector<Detection> ChooseTemplates(const std::vector<Candidate>& candidates,
                                       const std::vector<double>& thresholds,
                                       const std::vector<char>& far,
                                       const std::vector<std::optional<double>>& prior_theta,
                                       int held_cluster, int evidence_exempt_cluster,
                                       bool off_floor, const EstimatorOptions& o) {
  std::map<int, std::vector<const Candidate*>> by_cluster;
  for (const Candidate& c : candidates) by_cluster[c.cluster_index].push_back(&c);
  std::vector<Detection> out;
  for (auto& [cluster, cands] : by_cluster) {
    // Posed candidates first, then by refined fit (or score), then by score.
    std::stable_sort(cands.begin(), cands.end(), [](const Candidate* a, const Candidate* b) {
      if (a->stopped_below_threshold != b->stopped_below_threshold)
        return !a->stopped_below_threshold;
      if (a->refined && b->refined && a->fit.fit != b->fit.fit) return a->fit.fit > b->fit.fit;
      return a->score > b->score;
    });
    size_t from_prior = 0;
    if (o.prior_heading_across_templates && prior_theta[cluster]) {
      from_prior = PriorHeadingChoice(cands, *prior_theta[cluster], o.min_humanoid_fit);
      // That one first, the others in their order.
      std::rotate(cands.begin(), cands.begin() + from_prior, cands.begin() + from_prior + 1);
    }
    Detection d;
    d.best = *cands.front();
    if (from_prior > 0) {  // taken over a fit as good facing the other way.
      d.best.heading_ambiguous = true;
      d.best.heading_from_prior = true;
    }
    d.score_threshold = thresholds[cluster];
    d.refused_by =
        HumanoidRefusal(d.best, d.score_threshold, cluster == evidence_exempt_cluster, o);
    // A far cluster below the full threshold passes on strong refined evidence only.
    if (d.refused_by == Refusal::kNone && far[cluster] && d.best.score < o.score_threshold &&
        HumanoidEvidenceShare(d.best) < o.far_min_evidence) {
      d.refused_by = Refusal::kFarEvidence;
    }
    if (d.refused_by == Refusal::kNone && off_floor && cluster != held_cluster &&
        !(d.best.template_voxels > 0 &&
          d.best.hits >= o.height_offset_min_coverage * d.best.template_voxels)) {
      d.refused_by = Refusal::kOffFloorCoverage;
    }
    d.is_humanoid = d.refused_by == Refusal::kNone;
    if (cands.size() > 1) {
      const Candidate& second = *cands[1];
      d.second_template = second.template_name;
      if (d.best.refined && second.refined) {
        d.template_margin = d.best.fit.fit - second.fit.fit;
        d.template_margin_kind = MarginKind::kFit;
        d.template_ambiguous = WithinNoise(d.best.fit, second.fit);
      } else if (second.stopped_below_threshold) {
        // Its score is a pose's it met on the way, not its optimum: the bound says how far
        // behind it is at least.
        d.template_margin = d.best.score - second.score_upper_bound;
        d.template_margin_kind = MarginKind::kScoreAtLeast;
      } else {
        d.template_margin = d.best.score - second.score;
      }
    } else {
      d.template_margin = d.best.score;
    }
    out.push_back(d);
  }
  // Humanoids first (a clutter cluster may outscore the humanoid and fail the fit), the one with
  // the most evidence first (HumanoidEvidence: a high score alone may be a small object).
  std::stable_sort(out.begin(), out.end(), DetectionBefore);
  return out;
}

// The search's voxel edge (EstimatorOptions::resolution_from_templates, max_height_voxels).
Result<double> SearchEdge(const EstimatorOptions& o, const std::vector<VoxelTemplate>& templates) {
  if (!o.resolution_from_templates) {
    for (const VoxelTemplate& t : templates) {
      if (t.resolution_m > o.lattice.resolution_m + 1e-9) {
        return MakeError(ErrorCode::kInvalidArgument,
                         "template '" + t.name + "' has voxels of " +
                             VoxelEdgeText(t.resolution_m) + ", coarser than the search's " +
                             VoxelEdgeText(o.lattice.resolution_m) +
                             " (its resolution): make the template at that edge or finer, or "
                             "search at the templates' own");
      }
    }
    return o.lattice.resolution_m;
  }
  double edge = 0.0, tallest = 0.0;
  for (const VoxelTemplate& t : templates) {
    edge = std::max(edge, t.resolution_m);
    tallest = std::max(tallest, t.Height());
  }
  return TallBodySearchEdge(tallest, edge, o.max_height_voxels);
}

// Whether a pose (e.g. the previous frame's) stands on the cluster: within a hand of its
// footprint.
bool StandsOn(const Cluster& c, const Pose2D& pose) {
  constexpr float kFootprintMargin = 0.15f;  // metres.
  return pose.x >= c.min.x() - kFootprintMargin && pose.x <= c.max.x() + kFootprintMargin &&
         pose.y >= c.min.y() - kFootprintMargin && pose.y <= c.max.y() + kFootprintMargin;
}

// The heights off the floor (metres) at which a frame whose humanoid did not pass at
// `first_offset` searches again (EstimatorOptions::height_offset_voxels, of `edge` metres): in
// rounds of equal size, the floor itself first when the frame started off it, then one voxel
// lower and higher, then two, ...; with `turn` >= 0, only the turn-th of them in that order
// (modulo their number), alone (FramePrior::height_offset_turn).
std::vector<std::vector<double>> HeightOffsetRounds(int voxels, double edge, double first_offset,
                                                    int turn) {
  std::vector<std::vector<double>> rounds;
  std::vector<double> every;
  for (int k = 0; k <= voxels; ++k) {
    std::vector<double> round;
    for (const int sign : {-1, 1}) {
      const double offset = sign * k * edge;
      if ((k == 0 && sign > 0) || std::abs(offset - first_offset) < 1e-9) continue;
      round.push_back(offset);
      every.push_back(offset);
    }
    if (!round.empty()) rounds.push_back(std::move(round));
  }
  if (turn < 0 || every.empty()) return rounds;
  return {{every[static_cast<size_t>(turn) % every.size()]}};
}

// The cluster the prior's humanoid stood on: the nearest by centroid of those it stands on;
// -1 when none (or no prior).
int HeldCluster(const std::vector<Cluster>& clusters, const FramePrior* prior) {
  if (prior == nullptr || !prior->has_pose) return -1;
  int held = -1;
  double nearest = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < clusters.size(); ++i) {
    if (!StandsOn(clusters[i], prior->pose)) continue;
    const double d = std::hypot(clusters[i].centroid.x() - prior->pose.x,
                                clusters[i].centroid.y() - prior->pose.y);
    if (d < nearest) {
      nearest = d;
      held = static_cast<int>(i);
    }
  }
  return held;
}

// The floor raised by `dz` metres along its normal: the ground frame's origin that much higher.
FloorEstimate RaiseFloor(const FloorEstimate& floor, double dz) {
  FloorEstimate raised = floor;
  if (dz == 0.0) return raised;
  raised.plane_sensor[3] -= dz;
  raised.ground_from_sensor.pretranslate(Eigen::Vector3d(0.0, 0.0, -dz));
  raised.height_m -= dz;
  return raised;
}

// The clusters as seen from a floor raised by `dz` metres (RaiseFloor).
std::vector<Cluster> LowerClusters(const std::vector<Cluster>& clusters, double dz) {
  std::vector<Cluster> lowered = clusters;
  const Eigen::Vector3f down(0.0f, 0.0f, static_cast<float>(dz));
  for (Cluster& c : lowered) {
    for (Eigen::Vector3f& p : c.points) p -= down;
    c.centroid -= down;
    c.min -= down;
    c.max -= down;
  }
  return lowered;
}

bool FoundHumanoid(const Estimate& est) {
  return !est.detections.empty() && est.detections.front().is_humanoid;
}

// A cluster's extent across the line of sight from the sensor (ground origin) to its centroid.
double ApparentWidth(const Cluster& c) {
  Eigen::Vector2f u = c.centroid.head<2>();
  if (u.norm() < 1e-6) return 0.0;
  u.normalize();
  const Eigen::Vector2f across(-u.y(), u.x());
  float lo = 1e9f, hi = -1e9f;
  for (const Eigen::Vector3f& p : c.points) {
    const float w = across.dot(p.head<2>());
    lo = std::min(lo, w);
    hi = std::max(hi, w);
  }
  return hi >= lo ? hi - lo : 0.0;
}

}  // namespace

double TallBodySearchEdge(double height_m, double resolution_m, int max_height_voxels) {
  if (max_height_voxels <= 0 || !(height_m > max_height_voxels * resolution_m + 1e-9)) {
    return resolution_m;
  }
  return std::ceil(height_m / max_height_voxels * 1000.0 - 1e-6) / 1000.0;
}

Estimator::Estimator(EstimatorOptions options, std::vector<VoxelTemplate> templates,
                     std::vector<VoxelTemplate> searched, const std::vector<TemplateModels>& shared)
    : options_(std::move(options)),
      templates_(std::move(templates)),
      searched_(std::move(searched)) {
  pool_ = std::make_unique<TaskPool>(TaskPool::Resolve(options_.threads));
  // Each template's rotations and surface, two tasks per template for the threads; taken from
  // `shared` where they were made alike.
  const int count = static_cast<int>(templates_.size());
  rotations_.resize(count);
  surfaces_.resize(count);
  silhouette_widths_.resize(count);
  const double spacing = options_.refine.surface_spacing_m;
  for (int j = 0; j < count; ++j) {
    const VoxelTemplate& t = searched_[j];
    for (const TemplateModels& m : shared) {
      const PoseLattice& a = m.lattice;
      const PoseLattice& b = options_.lattice;
      if (m.rotations == nullptr || m.surface == nullptr || m.rotations->name() != t.name ||
          m.rotations->voxels() != t.voxels.size() || a.resolution_m != b.resolution_m ||
          a.subdivisions != b.subdivisions || a.angle_steps != b.angle_steps ||
          m.surface_spacing_m != spacing) {
        continue;
      }
      rotations_[j] = m.rotations;
      surfaces_[j] = m.surface;
      break;
    }
  }
  // The search's models from the templates at its edge; the refinement's surface from each
  // template as it was made.
  pool_->ParallelFor(2 * count, [&](int k) {
    const VoxelTemplate& t = searched_[k / 2];
    if (k % 2 == 0) {
      if (rotations_[k / 2] == nullptr) {
        rotations_[k / 2] = std::make_shared<const TemplateRotations>(t, options_.lattice);
      }
    } else {
      if (surfaces_[k / 2] == nullptr) {
        surfaces_[k / 2] = std::make_shared<const SurfaceModel>(templates_[k / 2], spacing);
      }
      silhouette_widths_[k / 2] = SilhouetteWidths(t, options_.clusters.min_height_above_floor_m);
    }
  });
  search_ = MakeSearch(options_);
  // The free space every template's search may read, height by height.
  for (size_t j = 0; j < searched_.size() && search_ != nullptr; ++j) {
    const std::vector<int> grow = FreeSpaceGrow(searched_[j], search_->OriginMargin(*rotations_[j]),
                                                options_.lattice.resolution_m);
    if (grow.size() > free_grow_.size()) free_grow_.resize(grow.size(), -1);
    for (size_t z = 0; z < grow.size(); ++z) free_grow_[z] = std::max(free_grow_[z], grow[z]);
  }
  if (options_.make_tables_at_start && options_.search == SearchKind::kExact) {
    // Runs of rotations a whole number of the largest theta blocks long, for the threads.
    constexpr int kRun = 1 << (TemplateRotations::kThetaLevels - 1);
    const int steps = options_.lattice.angle_steps;
    const int runs = (steps + kRun - 1) / kRun;
    pool_->ParallelFor(static_cast<int>(rotations_.size()) * runs, [&](int k) {
      const int begin = (k % runs) * kRun;
      rotations_[k / runs]->MakeTables(options_.exact.top_theta_level, begin, begin + kRun);
    });
    // ... and the queues of a frame's searches: every (cluster, template) search keeps its
    // queue until its runner-up is known, so a frame holds about as many as it has searches
    // (the real-time protocol's frames up to 6), each for up to about 25 k blocks there
    // (docs/BENCHMARKS.md). About 10 MB.
    constexpr int kQueues = 8;
    constexpr size_t kQueuedBlocks = size_t{1} << 15;
    ExactSearch::ReserveQueues(kQueues, kQueuedBlocks);
  }
}

Estimator::~Estimator() = default;

std::vector<TemplateModels> Estimator::models() const {
  std::vector<TemplateModels> out(templates_.size());
  for (size_t j = 0; j < templates_.size(); ++j) {
    out[j].lattice = options_.lattice;
    out[j].surface_spacing_m = options_.refine.surface_spacing_m;
    out[j].rotations = rotations_[j];
    out[j].surface = surfaces_[j];
  }
  return out;
}

Result<std::unique_ptr<Estimator>> Estimator::Create(EstimatorOptions options,
                                                     std::vector<VoxelTemplate> templates,
                                                     const std::vector<TemplateModels>& shared) {
  if (templates.empty()) {
    return MakeError(ErrorCode::kInvalidArgument, "no templates given (at least one is needed)");
  }
  // Options that every frame would otherwise refuse are refused once, here (the lattice once
  // its edge is known).
  Status st = options.use_fixed_floor ? ValidateFloor(options.fixed_floor)
                                      : ValidateFloorFitterOptions(options.floor_fit);
  if (!st.ok()) return st.error();
  st = ValidateClusterOptions(options.clusters);
  if (!st.ok()) return st.error();
  st = ValidateDepthToCloudOptions(options.cloud);
  if (!st.ok()) return st.error();
  std::set<std::string> names;
  for (const VoxelTemplate& t : templates) {
    if (!names.insert(t.name).second) {
      return MakeError(ErrorCode::kInvalidArgument,
                       "two templates are named '" + t.name + "'; names must be unique");
    }
    if (t.voxels.empty()) {
      return MakeError(ErrorCode::kInvalidArgument, "template '" + t.name + "' has no voxels");
    }
  }
  if (options.height_offset_voxels < 0 || options.height_offset_voxels > 8) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "height_offset_voxels must be within [0, 8], got " +
                         std::to_string(options.height_offset_voxels));
  }
  if (!(options.height_offset_height_error >= 0.0)) {
    return MakeError(ErrorCode::kInvalidArgument, "height_offset_height_error must be >= 0");
  }
  if (!(options.height_offset_min_coverage >= 0.0 && options.height_offset_min_coverage <= 1.0)) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "height_offset_min_coverage must be within [0, 1]");
  }
  if (options.max_height_voxels != 0 &&
      (options.max_height_voxels < 8 || options.max_height_voxels > 1024)) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "max_height_voxels must be 0 (off) or within [8, 1024], got " +
                         std::to_string(options.max_height_voxels));
  }
  if (!options.resolution_from_templates) {
    st = options.lattice.Validate();
    if (!st.ok()) return st.error();
  }
  Result<double> edge = SearchEdge(options, templates);
  if (!edge.ok()) return edge.error();
  options.lattice.resolution_m = *edge;
  st = options.lattice.Validate();
  if (!st.ok()) return st.error();
  std::vector<VoxelTemplate> searched;
  for (const VoxelTemplate& t : templates) {
    if (std::abs(t.resolution_m - *edge) <= 1e-9) {
      searched.push_back(t);
      continue;
    }
    Result<VoxelTemplate> again = VoxeliseAgain(t, *edge);
    if (!again.ok()) return again.error();
    searched.push_back(std::move(*again));
  }
  if (options.threads < 0 || options.threads > 256) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "threads must be within [0, 256] (0: one per core), got " +
                         std::to_string(options.threads));
  }
  if (!(options.score_threshold >= 0.0 && options.score_threshold <= 100.0)) {
    return MakeError(ErrorCode::kInvalidArgument, "score_threshold must be within [0, 100]");
  }
  if (!(options.min_humanoid_fit >= 0.0 && options.min_humanoid_fit <= 100.0)) {
    return MakeError(ErrorCode::kInvalidArgument, "min_humanoid_fit must be within [0, 100]");
  }
  if (!(options.min_humanoid_evidence >= 0.0 && options.min_humanoid_evidence <= 1.0)) {
    return MakeError(ErrorCode::kInvalidArgument, "min_humanoid_evidence must be within [0, 1]");
  }
  if (!(options.tracked_hold_min_evidence >= 0.0 && options.tracked_hold_min_evidence <= 1.0)) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "tracked_hold_min_evidence must be within [0, 1]");
  }
  if (!(options.tracked_score_threshold >= 0.0 && options.tracked_score_threshold <= 100.0)) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "tracked_score_threshold must be within [0, 100]");
  }
  if (!(options.tracked_heading_confirm_rad >= 0.0 && options.tracked_heading_confirm_rad <= kPi)) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "tracked_heading_confirm_rad must be within [0, pi] (radians; 0: off)");
  }
  if (!(options.tracked_other_template_margin <= 100.0)) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "tracked_other_template_margin must be at most 100 (score points; "
                     "negative: off)");
  }
  if (!(options.range_image_edge_band >= 0.0 && options.range_image_edge_band < 0.5)) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "range_image_edge_band must be within [0, 0.5) (a share of the image's rows)");
  }
  if (!(options.two_points_a_voxel_within_m >= 0.0)) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "two_points_a_voxel_within_m must be at least 0 (metres; 0: off)");
  }
  if (!(options.free_space.steep_ray_rad >= 0.0)) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "free_space.steep_ray_rad must be at least 0 (radians; above pi/2: off)");
  }
  if (!(options.far_range_m >= 0.0)) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "far_range_m must be at least 0 (metres; infinity: no far clusters)");
  }
  if (!(options.far_score_ratio >= 0.0 && options.far_score_ratio <= 1.0)) {
    return MakeError(ErrorCode::kInvalidArgument, "far_score_ratio must be within [0, 1]");
  }
  if (!(options.far_min_evidence >= 0.0 && options.far_min_evidence <= 1.0)) {
    return MakeError(ErrorCode::kInvalidArgument, "far_min_evidence must be within [0, 1]");
  }
  std::unique_ptr<Estimator> e(
      new Estimator(std::move(options), std::move(templates), std::move(searched), shared));
  if (e->search_ == nullptr) {
    return MakeError(ErrorCode::kInvalidArgument, std::string("search '") +
                                                      SearchKindName(e->options_.search) +
                                                      "' is not available in this build");
  }
  return e;
}

Result<Estimate> Estimator::EstimateDepth(const DepthImage& depth, const Intrinsics& intrinsics,
                                          const FramePrior* prior) const {
  const Clock::time_point t0 = Clock::now();
  Result<PointCloud> cloud = DepthToCloud(depth, intrinsics, options_.cloud);
  if (!cloud.ok()) return cloud.error();
  if (cloud->empty()) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "no depth to estimate from: " + NoPointInRangeReason(depth, options_.cloud));
  }
  // The rays through the outermost pixel centres: DepthToCloud's (u - cx) / fx, (v - cy) / fy.
  ImageEdges edges;
  edges.left_tan = -intrinsics.cx / intrinsics.fx;
  edges.right_tan = (intrinsics.width - 1 - intrinsics.cx) / intrinsics.fx;
  edges.top_tan = -intrinsics.cy / intrinsics.fy;
  edges.bottom_tan = (intrinsics.height - 1 - intrinsics.cy) / intrinsics.fy;
  edges.pixel_tan = 1.0 / intrinsics.fx;
  return Run(*cloud, MsSince(t0), prior, edges);
}

Result<Estimate> Estimator::EstimateCloud(const PointCloud& cloud_sensor,
                                          const FramePrior* prior) const {
  return Run(cloud_sensor, 0.0, prior, ImageEdges{});
}

void Estimator::SearchClusters(const std::vector<Cluster>& on_floor, const RangeImage& range,
                               const ImageEdges& edges, const FramePrior* prior,
                               double height_offset_m, Estimate* out) const {
  Estimate& est = *out;
  // The templates stand height_offset_m above the floor: the floor and the clusters as seen
  // from a floor raised that much.
  const FloorEstimate floor = RaiseFloor(est.floor, height_offset_m);
  std::vector<Cluster> moved;
  if (height_offset_m != 0.0) moved = LowerClusters(on_floor, height_offset_m);
  const std::vector<Cluster>* clusters = height_offset_m != 0.0 ? &moved : &on_floor;
  // The cluster the previous frame's humanoid stood on, if any, and its lower threshold.
  const int held_cluster = HeldCluster(*clusters, prior);
  est.tracking.held_cluster = held_cluster;
  // ... exempt from min_humanoid_evidence where its track has shown tracked_hold_min_evidence.
  const int evidence_exempt = held_cluster >= 0 && prior->hold_confirmed ? held_cluster : -1;
  // The previous frame's template, whose refinement on the held cluster comes before the
  // others' (EstimatorOptions::tracked_other_template_margin); -1 when none or off.
  int prior_tpl = -1;
  if (held_cluster >= 0 && options_.tracked_other_template_margin >= 0.0) {
    for (size_t j = 0; j < rotations_.size(); ++j) {
      if (rotations_[j]->name() == prior->template_name) prior_tpl = static_cast<int>(j);
    }
  }
  const double tracked_threshold =
      std::min(options_.tracked_score_threshold, options_.score_threshold);
  std::vector<double> thresholds(clusters->size(), options_.score_threshold);

  const bool use_free_space = options_.score == ScoreKind::kFreeSpace;
  const bool refine = options_.refine.enabled;
  // The held cluster's templates other than the previous frame's search only until they are
  // proved far behind it (EstimatorOptions::tracked_other_template_stops; without refinement
  // none is left behind).
  const bool stop_behind = refine && options_.tracked_other_template_stops;
  // Runner-ups are searched for once the refined fits are known: only the templates that
  // contend on their cluster need them.
  const bool defer_runner_ups = refine && !options_.refine.search_far_behind_runner_up &&
                                options_.refine.runner_up_fit_sigmas > 0.0;
  const Eigen::Isometry3d sensor_from_ground = floor.ground_from_sensor.inverse();
  const Eigen::Vector3d sensor_in_ground(0.0, 0.0, floor.height_m);
  const TopOfView top_of_view = TopOfViewOf(range, edges, floor);
  const SideEdges side_edges = SideEdgesOf(range, edges, est.floor);
  // Free space along steep rays is read from the nearest depth around them
  // (FreeSpaceOptions::steep_ray_rad); most mounts have none, and read the range image itself.
  RangeImage steep_range;
  const RangeImage* free_range = &range;
  if (use_free_space &&
      range.HasSteepRays(floor.ground_from_sensor, options_.free_space.steep_ray_rad)) {
    steep_range =
        range.NearestAroundSteepRays(floor.ground_from_sensor, options_.free_space.steep_ray_rad);
    free_range = &steep_range;
  }
  // What each cluster shares between its templates' searches.
  struct ClusterWork {
    ClusterVoxels voxels;
    ClusterVoxels free;
    int n = 0;  // cluster voxels (the score's denominator).
    // What the searches of its templates share (the search's occupancy grids), if anything.
    std::vector<const TemplateRotations*> searched_with;
    std::shared_ptr<const SearchGrids> grids;
    // The refinement's cluster side, made by the first of its templates to need it.
    std::once_flag prepare_once;
    std::optional<PreparedCluster> prepared;
  };
  struct Task {
    int cluster = 0;
    int tpl = 0;
    double threshold = 0.0;  // the score threshold it is searched down to.
    bool kept = false;       // passed the voxel-count bound.
    bool far = false;        // a far cluster's (EstimatorOptions::far_range_m), not the held one.
    // A far task's search that stopped below score_threshold, kept to go on below it.
    std::unique_ptr<StoppedSearch> stopped;
    bool seeded = false;  // the prior pose lay in its search region.
    Candidate cand;
    bool has_prior = false;  // the previous frame's pose stood on this cluster.
    double prior_theta = 0.0;
    double refine_ms = 0.0;
    // The search's scorer, kept for the rescore of a runner-up that wins.
    std::unique_ptr<PoseScorer> scorer;
    // The runner-up's search, left until the refined fits say whether it is needed.
    std::unique_ptr<RunnerUpSearch> runner_up;
    // Its refinement waits for the previous frame's template's on the held cluster
    // (EstimatorOptions::tracked_other_template_margin).
    bool refine_deferred = false;
    // Above `threshold`: the score its search may stop below, that template's less the margin
    // (EstimatorOptions::tracked_other_template_stops); its stopped search is then kept.
    double stop_below = 0.0;
  };
  const int cluster_count = static_cast<int>(clusters->size());
  std::vector<ClusterWork> work(cluster_count);
  std::vector<Task> tasks;
  std::vector<int> searched_clusters;
  for (int i = 0; i < cluster_count; ++i) {
    const Cluster& c = (*clusters)[i];
    const double width = ApparentWidth(c);
    const double visible_top = options_.height_check_uses_view
                                   ? top_of_view.HeightAbove(c)
                                   : std::numeric_limits<double>::infinity();
    // Cut by the image's side, a cluster need show only half the height (lazily: a point
    // transform each).
    std::optional<bool> cut_at_side;
    const size_t before = tasks.size();
    for (size_t j = 0; j < templates_.size(); ++j) {
      const TemplateRotations& rot = *rotations_[j];
      if (options_.max_height_ratio_error >= 0.0) {
        // The template shows up to its top, or up to where the view ends above the cluster.
        const double e = height_offset_m != 0.0 ? std::min(options_.max_height_ratio_error,
                                                           options_.height_offset_height_error)
                                                : options_.max_height_ratio_error;
        const double shown = std::min(rot.height_m(), std::max(visible_top, 0.0));
        if (c.height() > (1.0 + e) * rot.height_m()) continue;
        if (c.height() < (1.0 - e) * shown) {
          if (!options_.height_check_uses_view || c.height() < kSideCutShare * shown) continue;
          if (!cut_at_side) cut_at_side = side_edges.Cuts(on_floor[i]);
          if (!*cut_at_side) continue;
        }
      }
      const auto [narrow, wide] = silhouette_widths_[j];
      if (options_.min_width_ratio >= 0.0 && width < options_.min_width_ratio * narrow) continue;
      if (options_.max_width_ratio >= 0.0 && width > options_.max_width_ratio * wide) continue;
      Task task;
      task.cluster = i;
      task.tpl = static_cast<int>(j);
      tasks.push_back(std::move(task));
    }
    if (tasks.size() > before) searched_clusters.push_back(i);
  }

  for (const Task& task : tasks)
    work[task.cluster].searched_with.push_back(rotations_[task.tpl].get());
  // Voxels and free space of every cluster that has a template to search, one cluster per
  // thread.
  const double res = options_.lattice.resolution_m;
  pool_->ParallelFor(static_cast<int>(searched_clusters.size()), [&](int k) {
    const int i = searched_clusters[k];
    const Cluster& c = (*clusters)[i];
    ClusterWork& w = work[i];
    const bool near = (c.centroid.cast<double>() - sensor_in_ground).norm() <
                      options_.two_points_a_voxel_within_m;
    w.voxels = VoxeliseCluster(c.points, res, near);
    w.n = static_cast<int>(w.voxels.cells.size());  // what every scorer counts.
    if (use_free_space && !w.voxels.cells.empty()) {
      // Wherever a template placed by the searches can reach, height by height.
      w.free =
          FreeSpaceCells(*free_range, sensor_from_ground,
                         FreeSpaceRegionAround(w.voxels, free_grow_), res, options_.free_space);
    }
    if (w.searched_with.size() > 1) {
      w.grids = search_->MakeGrids(w.voxels, use_free_space ? &w.free : nullptr, w.searched_with);
    }
  });

  // What the refinements of a cluster's templates read, with its prepared side once made.
  const auto observation_of = [&](int cluster) {
    const ClusterWork& w = work[cluster];
    return Observation{&(*clusters)[cluster].points, &range, sensor_from_ground,
                       w.prepared ? &*w.prepared : nullptr};
  };
  // The refinement of a task's optimum.
  const auto refine_task = [&](Task& task) {
    const Cluster& c = (*clusters)[task.cluster];
    ClusterWork& w = work[task.cluster];
    const Clock::time_point t_refine = Clock::now();
    std::call_once(w.prepare_once,
                   [&] { w.prepared.emplace(c.points, sensor_from_ground, options_.refine); });
    RefineBest(*surfaces_[task.tpl], observation_of(task.cluster), options_.refine, &task.cand);
    task.refine_ms = MsSince(t_refine);
  };
  // The task's candidate from its search's result, refined when the search did not stop.
  const auto finish_task = [&](Task& task, const SearchResult& r) {
    task.seeded = r.incumbent_used;
    Candidate& cand = task.cand;
    cand.template_name = rotations_[task.tpl]->name();
    cand.cluster_index = task.cluster;
    cand.height_offset_m = height_offset_m;
    cand.pose = r.pose;
    cand.lattice_pose = r.pose;
    cand.score = r.score;
    cand.coverage = r.coverage;
    cand.stopped_below_threshold = r.below_min_value;
    cand.score_upper_bound = r.below_min_value ? r.score_upper_bound : r.score;
    cand.free_space_hits = r.free_hits;
    cand.hits = r.hits;
    cand.cluster_voxels = work[task.cluster].n;
    cand.template_voxels = static_cast<int>(searched_[task.tpl].voxels.size());
    cand.has_runner_up = r.has_runner_up;
    cand.runner_up_pose = r.runner_up_pose;
    cand.runner_up_score = r.runner_up_score;
    cand.poses_evaluated = r.poses_evaluated;
    cand.bounds_evaluated = r.bounds_evaluated;
    if (!refine || r.below_min_value) return;
    // The previous frame's template's refinement too waits, for its score to set where the
    // others' searches may stop (EstimatorOptions::tracked_other_template_stops).
    if (task.cluster == held_cluster && prior_tpl >= 0 && (task.tpl != prior_tpl || stop_behind)) {
      task.refine_deferred = true;
    } else {
      refine_task(task);
    }
  };
  // A score threshold as the search's min_value on a cluster of n voxels.
  const auto min_value_of = [&](double threshold, int n) {
    return static_cast<int>(std::ceil(threshold * options_.hit_weight * n / 100.0 - 1e-9));
  };
  // Every (cluster, template) search and its refinement, one per thread; each task has its own
  // scorer (scorers keep scratch space).
  const auto search_task = [&](Task& task) {
    const Cluster& c = (*clusters)[task.cluster];
    ClusterWork& w = work[task.cluster];
    const int j = task.tpl;
    const TemplateRotations& rot = *rotations_[j];
    // A bound, not a heuristic: a placed template covers at most as many cluster voxels as it
    // has voxels, so a cluster that large cannot reach the threshold with it.
    const int n = w.n;
    const double threshold = task.threshold;
    if (threshold > 0.0 && n > 0 &&
        100.0 * static_cast<double>(searched_[j].voxels.size()) / n < threshold) {
      return;
    }
    task.kept = true;
    task.scorer = MakePoseScorer(options_.scorer, w.voxels, options_.lattice);
    SearchProblem problem;
    problem.cluster = &w.voxels;
    problem.scorer = task.scorer.get();
    problem.rotations = &rot;
    problem.centre_ground = c.centroid.head<2>().cast<double>();
    problem.free_space = use_free_space ? &w.free : nullptr;
    problem.grids = w.grids.get();
    problem.free_space_weight = options_.free_space_weight;
    problem.hit_weight = options_.hit_weight;
    if (options_.stop_below_threshold) problem.min_value = min_value_of(threshold, n);
    const bool stops_behind = task.stop_below > threshold;
    if (stops_behind) problem.optimum_min_value = min_value_of(task.stop_below, n);
    if (options_.refine.runner_up_within_score_window) {
      // Every runner-up within the window of the optimum's score is found: a value of at
      // least the optimum's less this.
      const double window =
          options_.refine.runner_up_score_window * options_.hit_weight * n / 100.0 + 1e-9;
      if (window < static_cast<double>(std::numeric_limits<int>::max())) {
        problem.runner_up_window = static_cast<int>(std::floor(std::max(window, 0.0)));
      }
    }
    // The prior pose seeds the search of the cluster it stands on (within a hand of its
    // footprint), for every template: the bodies differ little.
    LatticePose incumbent;
    if (prior != nullptr && prior->has_pose && StandsOn(c, prior->pose)) {
      incumbent = NearestLatticePose(options_.lattice, prior->pose);
      problem.incumbent = &incumbent;
      task.has_prior = true;
      task.prior_theta = prior->pose.theta;
    }
    SearchResult r;
    task.runner_up =
        search_->SearchBest(problem, &r, task.far || stops_behind ? &task.stopped : nullptr);
    if (!defer_runner_ups && task.runner_up != nullptr) {
      task.runner_up->Find(&r);
      task.runner_up.reset();
    }
    finish_task(task, r);
  };
  // A task searched anew down to `threshold` (its earlier search stopped above it, or its voxel
  // count ruled it out there).
  const auto search_again = [&](Task& task, double threshold) {
    Task fresh;
    fresh.cluster = task.cluster;
    fresh.tpl = task.tpl;
    fresh.threshold = threshold;
    task = std::move(fresh);
    search_task(task);
  };
  // A task whose search stopped above `threshold` goes on down to it from where it stopped, or
  // is searched anew there when it kept nothing (or was not searched: its voxel count).
  const auto go_on = [&](Task& task, double threshold, int min_value) {
    task.threshold = threshold;
    task.stop_below = 0.0;
    if (task.stopped == nullptr) {
      search_again(task, threshold);
      return;
    }
    SearchResult r;
    task.runner_up = task.stopped->Lower(min_value, &r);
    task.stopped.reset();
    if (!defer_runner_ups && task.runner_up != nullptr) {
      task.runner_up->Find(&r);
      task.runner_up.reset();
    }
    finish_task(task, r);
  };
  // A prior that passed by the lower threshold itself: its cluster goes straight down to it.
  if (held_cluster >= 0 && prior->score < options_.score_threshold) {
    thresholds[held_cluster] = tracked_threshold;
  }
  // Far clusters other than the held one (EstimatorOptions::far_range_m) keep their stopped
  // searches, to go on below score_threshold if nothing passes it.
  const double far_threshold = options_.far_score_ratio * options_.score_threshold;
  for (Task& task : tasks) {
    task.threshold = thresholds[task.cluster];
    task.far = refine && task.cluster != held_cluster && far_threshold < task.threshold &&
               ((*clusters)[task.cluster].centroid.cast<double>() - sensor_in_ground).norm() >=
                   options_.far_range_m;
  }
  // The held cluster's other templates may wait for the previous frame's template's search and
  // stop once they are proved far behind it (stop_behind).
  std::vector<int> first, behind;
  int lead_k = -1;  // the held cluster's task of the previous frame's template, if any.
  for (int k = 0; k < static_cast<int>(tasks.size()); ++k) {
    const Task& task = tasks[k];
    const bool held_other = task.cluster == held_cluster && prior_tpl >= 0 && task.tpl != prior_tpl;
    (held_other && stop_behind ? behind : first).push_back(k);
    if (task.cluster == held_cluster && prior_tpl >= 0 && task.tpl == prior_tpl) lead_k = k;
  }
  if (lead_k < 0) {
    first.insert(first.end(), behind.begin(), behind.end());
    behind.clear();
  }
  pool_->ParallelFor(static_cast<int>(first.size()), [&](int i) { search_task(tasks[first[i]]); });
  if (!behind.empty()) {
    // They search while the lead is refined.
    Task& lead = tasks[lead_k];
    if (lead.kept && !lead.cand.stopped_below_threshold) {
      for (int k : behind) {
        tasks[k].stop_below = lead.cand.score - options_.tracked_other_template_margin;
      }
    }
    std::vector<int> work_items = behind;
    if (lead.refine_deferred) work_items.push_back(lead_k);
    pool_->ParallelFor(static_cast<int>(work_items.size()), [&](int i) {
      Task& task = tasks[work_items[i]];
      if (work_items[i] == lead_k) {
        task.refine_deferred = false;
        refine_task(task);
      } else {
        search_task(task);
      }
    });
  }
  // Hysteresis: when none of the held cluster's templates reached score_threshold, those whose
  // search stopped below it or that its voxel count ruled out are searched again down to
  // tracked_score_threshold (a search that was not stopped has its optimum already).
  if (held_cluster >= 0 && thresholds[held_cluster] > tracked_threshold) {
    std::vector<int> again;
    bool passed = false;
    for (int k = 0; k < static_cast<int>(tasks.size()); ++k) {
      const Task& task = tasks[k];
      if (task.cluster != held_cluster) continue;
      const bool done = task.kept && !task.cand.stopped_below_threshold;
      passed = passed || (done && task.cand.score >= options_.score_threshold);
      if (!done) again.push_back(k);
    }
    if (!passed) {
      thresholds[held_cluster] = tracked_threshold;
      pool_->ParallelFor(static_cast<int>(again.size()),
                         [&](int i) { search_again(tasks[again[i]], tracked_threshold); });
    }
  }
  // The held cluster's other templates: refined unless the previous frame's template passes
  // there and the search put them more than tracked_other_template_margin points behind it.
  {
    Task* lead = lead_k >= 0 && tasks[lead_k].kept ? &tasks[lead_k] : nullptr;
    // Searched again down to the tracked threshold above, its refinement waited (stop_behind):
    // first of all now, since whether the others are refined depends on it.
    if (lead != nullptr && lead->refine_deferred) {
      lead->refine_deferred = false;
      refine_task(*lead);
    }
    const bool lead_passes = lead != nullptr && lead->cand.refined &&
                             PassesAsHumanoid(lead->cand, thresholds[held_cluster],
                                              evidence_exempt == held_cluster, options_);
    // A search that stopped behind the lead goes on down to its threshold where the lead does
    // not pass, and its template is refined below.
    std::vector<int> behind_lead;
    for (int k = 0; k < static_cast<int>(tasks.size()); ++k) {
      Task& task = tasks[k];
      if (!(task.stop_below > task.threshold)) continue;
      if (lead_passes || !task.cand.stopped_below_threshold) {
        task.stopped.reset();
      } else {
        behind_lead.push_back(k);
      }
    }
    pool_->ParallelFor(static_cast<int>(behind_lead.size()), [&](int i) {
      Task& task = tasks[behind_lead[i]];
      // As far down as its search would have gone without the lead.
      go_on(task, task.threshold,
            options_.stop_below_threshold ? min_value_of(task.threshold, work[task.cluster].n)
                                          : std::numeric_limits<int>::min());
    });
    std::vector<int> deferred;
    for (int k = 0; k < static_cast<int>(tasks.size()); ++k) {
      Task& task = tasks[k];
      if (!task.refine_deferred) continue;
      task.refine_deferred = false;
      if (lead_passes &&
          task.cand.score < lead->cand.score - options_.tracked_other_template_margin) {
        task.runner_up.reset();
        continue;
      }
      deferred.push_back(k);
    }
    pool_->ParallelFor(static_cast<int>(deferred.size()),
                       [&](int i) { refine_task(tasks[deferred[i]]); });
  }
  // Far clusters when nothing in the frame passed (a humanoid, or clutter refused by the fit):
  // Kinect noise lowers a far humanoid's score (EstimatorOptions::far_score_ratio). Their
  // searches that stopped below score_threshold go on down to the far threshold from where they
  // stopped; those its voxel count ruled out are searched. ChooseTemplates then asks strong
  // refined evidence of what passes only by the far threshold.
  std::vector<char> far(cluster_count, 0);
  bool passed = false;
  for (const Task& task : tasks) {
    const Candidate& c = task.cand;
    passed = passed || (task.kept && PassesAsHumanoid(c, thresholds[task.cluster],
                                                      task.cluster == evidence_exempt, options_));
  }
  std::vector<int> lower;
  for (int k = 0; k < static_cast<int>(tasks.size()); ++k) {
    Task& task = tasks[k];
    if (!passed && task.far) {
      far[task.cluster] = 1;
      thresholds[task.cluster] = far_threshold;
      // Not searched, or stopped: on down to the far threshold. (Not stopped: its optimum.)
      if (!(task.kept && !task.cand.stopped_below_threshold)) {
        lower.push_back(k);
        continue;
      }
    }
    task.stopped.reset();  // its queue back to the pool.
  }
  pool_->ParallelFor(static_cast<int>(lower.size()), [&](int i) {
    Task& task = tasks[lower[i]];
    go_on(task, far_threshold, min_value_of(far_threshold, work[task.cluster].n));
  });

  // The runner-up headings, once every template of a cluster has its refined fit: a template
  // whose fit is far behind the cluster's best has its runner-up only evaluated, or (unless
  // RefineOptions::search_far_behind_runner_up) not even searched for.
  // (Copies: the runner-ups may change the candidates' fits meanwhile.)
  const auto leaders = [&] {
    std::vector<std::optional<FitSummary>> leader(cluster_count);
    for (const Task& task : tasks) {
      if (!task.cand.refined) continue;
      std::optional<FitSummary>& l = leader[task.cluster];
      if (!l || task.cand.fit.fit > l->fit) l = task.cand.fit;
    }
    return leader;
  };
  const auto contends = [&](const Task& task, const std::vector<std::optional<FitSummary>>& l) {
    return Contends(task.cand.fit, *l[task.cluster], options_.refine.runner_up_fit_sigmas);
  };
  // The runner-up's search, if it was left until now.
  const auto find_runner_up = [](Task& task) {
    if (task.runner_up == nullptr) return;
    SearchResult r;
    task.runner_up->Find(&r);
    task.runner_up.reset();
    Candidate& cand = task.cand;
    cand.has_runner_up = r.has_runner_up;
    cand.runner_up_pose = r.runner_up_pose;
    cand.runner_up_score = r.runner_up_score;
    cand.poses_evaluated += r.poses_evaluated;
    cand.bounds_evaluated += r.bounds_evaluated;
  };
  const auto refine_runner_up = [&](Task& task, bool contend) {
    if (!task.cand.refined || !task.cand.has_runner_up) return;
    const Clock::time_point t_refine = Clock::now();
    const ClusterWork& w = work[task.cluster];
    const int j = task.tpl;
    const TemplateRotations& rot = *rotations_[j];
    const int n = w.n;
    // What the pose's search scores would be at another lattice pose (when the refined
    // runner-up replaces the search's optimum).
    const auto rescore = [&](Candidate* cd) {
      const LatticePose lp = NearestLatticePose(options_.lattice, cd->lattice_pose);
      const RotatedTemplate& rt = rot.Get(lp.itheta);
      cd->hits = task.scorer->Hits(rt, lp.ix, lp.iy);
      cd->free_space_hits =
          use_free_space
              ? MakePoseScorer(ScorerKind::kFast, w.free, options_.lattice)->Hits(rt, lp.ix, lp.iy)
              : 0;
      cd->coverage = n > 0 ? 100.0 * cd->hits / n : 0.0;
    };
    RefineRunnerUp(*surfaces_[j], observation_of(task.cluster), options_.refine,
                   options_.heading_views, options_.min_humanoid_fit,
                   task.has_prior ? &task.prior_theta : nullptr, contend, rescore, &task.cand);
    task.refine_ms += MsSince(t_refine);
  };
  // EstimatorOptions::tracked_heading_confirm_rad.
  const HeadingConfirmOptions confirm{options_.tracked_heading_confirm_rad,
                                      options_.min_humanoid_fit,
                                      options_.heading_views.max_fit_sigmas};
  const auto confirms_previous_heading = [&](Task& task) {
    const Clock::time_point t_check = Clock::now();
    const bool confirmed = ConfirmsPreviousHeading(
        *surfaces_[task.tpl], observation_of(task.cluster), task.cand.lattice_pose, task.cand.pose,
        task.cand.fit, task.prior_theta, confirm, options_.refine);
    task.refine_ms += MsSince(t_check);
    return confirmed;
  };
  const std::vector<std::optional<FitSummary>> leader = leaders();
  std::vector<int> with_runner_up;
  for (int k = 0; k < static_cast<int>(tasks.size()); ++k) {
    const Task& task = tasks[k];
    if (task.runner_up != nullptr || (task.cand.refined && task.cand.has_runner_up)) {
      with_runner_up.push_back(k);
    }
  }
  pool_->ParallelFor(static_cast<int>(with_runner_up.size()), [&](int i) {
    Task& task = tasks[with_runner_up[i]];
    const bool contend = !task.cand.refined || contends(task, leader);
    if (!contend && task.runner_up != nullptr) return;  // perhaps later, see below.
    if (task.runner_up != nullptr && task.has_prior && task.cand.refined &&
        confirms_previous_heading(task)) {
      task.runner_up.reset();
      task.cand.heading_confirmed = true;
      return;
    }
    find_runner_up(task);
    refine_runner_up(task, contend);
  });
  // A cluster's leading template may have gone to its other heading with a poorer fit (the
  // depth images decided), and a template left behind may then be chosen: it gets its
  // runner-up, evaluated where it lies, as every template far behind did before.
  if (defer_runner_ups) {
    const std::vector<std::optional<FitSummary>> now = leaders();
    std::vector<int> again;
    for (int k = 0; k < static_cast<int>(tasks.size()); ++k) {
      Task& task = tasks[k];
      if (task.runner_up == nullptr) continue;
      if (contends(task, now)) {
        again.push_back(k);
      } else {
        task.runner_up.reset();
      }
    }
    pool_->ParallelFor(static_cast<int>(again.size()), [&](int i) {
      Task& task = tasks[again[i]];
      find_runner_up(task);
      refine_runner_up(task, false);
    });
  }
  double refine_ms = 0.0;  // summed over the candidates (CPU time, whatever the threads).
  for (Task& task : tasks) {
    if (!task.kept) continue;
    task.cand.refine_ms = task.refine_ms;
    est.candidates.push_back(task.cand);
    est.clusters[task.cluster].searched = true;
    refine_ms += task.refine_ms;
    est.tracking.tracked = est.tracking.tracked || task.seeded;
  }
  est.timings.refine_ms = refine_ms;

  std::stable_sort(est.candidates.begin(), est.candidates.end(),
                   [](const Candidate& a, const Candidate& b) { return a.score > b.score; });
  std::vector<std::optional<double>> prior_theta(cluster_count);
  for (const Task& task : tasks) {
    if (task.has_prior) prior_theta[task.cluster] = task.prior_theta;
  }
  est.detections = ChooseTemplates(est.candidates, thresholds, far, prior_theta, held_cluster,
                                   evidence_exempt, height_offset_m != 0.0, options_);
  // A humanoid's candidate whose free limbs moved is fitted again without them from its lattice
  // pose. Only its pose moves: its fit stays the whole template's, so which clusters pass and
  // which templates and headings were taken stay as chosen; candidates not taken, and clusters
  // refused, are left as they are (their refits would change no pose reported as a humanoid's).
  for (Detection& d : est.detections) {
    if (!d.is_humanoid || !d.best.refined || !d.best.free_limbs_moved) continue;
    for (const Task& task : tasks) {
      if (!task.kept || task.cluster != d.best.cluster_index ||
          rotations_[task.tpl]->name() != d.best.template_name) {
        continue;
      }
      const Clock::time_point t_refine = Clock::now();
      const RefinedPose again = RefineWithoutFreeLimbs(
          *surfaces_[task.tpl], observation_of(task.cluster), d.best.lattice_pose, options_.refine);
      const double ms = MsSince(t_refine);
      for (Candidate* cand : {&d.best, CandidateOf(&est.candidates, d.best)}) {
        if (cand == nullptr) continue;
        cand->pose = again.pose;
        cand->covariance = again.covariance;
        cand->free_limbs_left_out = again.free_limbs_left_out;
        cand->refine_ms += ms;
      }
      est.timings.refine_ms += ms;
      break;
    }
  }
}

Result<Estimate> Estimator::Run(const PointCloud& cloud, double cloud_ms, const FramePrior* prior,
                                const ImageEdges& edges) const {
  const Clock::time_point t_start = Clock::now();
  Estimate est;
  if (prior != nullptr && prior->has_pose) {
    est.tracking.prior_given = true;
    est.tracking.prior_template = prior->template_name;
    est.tracking.prior_pose = prior->pose;
  }
  est.timings.cloud_ms = cloud_ms;
  // Finite and bounded before PCL sees it; every point left is finite or missing (NaN).
  std::size_t finite = 0;
  const Status valid = ValidateCloud(cloud, {}, &finite);
  if (!valid.ok()) return valid.error();
  if (cloud.empty()) {
    return MakeError(ErrorCode::kInvalidArgument, "the point cloud is empty (no valid depth)");
  }
  if (finite == 0) {
    return MakeError(ErrorCode::kInvalidArgument, "the point cloud has no finite points (all " +
                                                      std::to_string(cloud.size()) +
                                                      " are NaN or infinite)");
  }
  est.cloud_points = static_cast<int>(finite);

  Clock::time_point t = Clock::now();
  if (options_.use_fixed_floor) {
    est.floor = options_.fixed_floor;
  } else if (prior != nullptr && prior->floor != nullptr) {
    Result<FloorEstimate> floor = prior->floor->Update(cloud);
    if (!floor.ok()) return floor.error();
    est.floor = *floor;
    est.tracking.floor_reused = !prior->floor->refitted();
  } else {
    Result<FloorEstimate> floor = FitFloor(cloud, options_.floor_fit);
    if (!floor.ok()) return floor.error();
    est.floor = *floor;
  }
  est.timings.floor_ms = MsSince(t);

  t = Clock::now();
  Result<std::vector<Cluster>> clusters = ExtractClusters(cloud, est.floor, options_.clusters);
  if (!clusters.ok()) return clusters.error();
  est.timings.cluster_ms = MsSince(t);
  for (int i = 0; i < static_cast<int>(clusters->size()); ++i) {
    const Cluster& c = (*clusters)[i];
    ClusterSummary summary;
    summary.index = i;
    summary.points = static_cast<int>(c.points.size());
    summary.centroid = c.centroid;
    summary.min = c.min;
    summary.max = c.max;
    est.clusters.push_back(summary);
  }

  t = Clock::now();
  RangeImage range;
  if (options_.score == ScoreKind::kFreeSpace || options_.refine.enabled) {
    // The image's rows but for a band at its top and bottom (EstimatorOptions::
    // range_image_spans_view, range_image_edge_band); its sides stay those of the readings.
    ViewSpan view;
    if (options_.range_image_spans_view) {
      const double band = options_.range_image_edge_band * (edges.bottom_tan - edges.top_tan);
      view.top = edges.top_tan + band;
      view.bottom = edges.bottom_tan - band;
    }
    range = RangeImage::FromCloud(cloud, options_.range_image_focal_px, view);
  }
  // The templates stand on the floor, or as high as the previous frame's humanoid stood.
  const double first_offset = prior != nullptr && prior->has_pose ? prior->height_offset_m : 0.0;
  SearchClusters(*clusters, range, edges, prior, first_offset, &est);
  // Nothing passed: the templates raised and lowered a voxel at a time (a robot with its knees
  // bent stands lower than its template, ...: EstimatorOptions::height_offset_voxels). The
  // first offsets at which something passes give the detections, the best fit of them.
  const std::vector<std::vector<double>> rounds =
      HeightOffsetRounds(options_.height_offset_voxels, options_.lattice.resolution_m, first_offset,
                         prior != nullptr ? prior->height_offset_turn : -1);
  for (size_t k = 0; !FoundHumanoid(est) && k < rounds.size(); ++k) {
    std::optional<Estimate> best;
    for (const double offset : rounds[k]) {
      Estimate trial;
      trial.floor = est.floor;
      trial.clusters = est.clusters;
      trial.tracking = est.tracking;
      SearchClusters(*clusters, range, edges, prior, offset, &trial);
      ++est.height_passes;
      est.timings.refine_ms += trial.timings.refine_ms;
      if (FoundHumanoid(trial) && (!best || trial.detections.front().best.fit.fit >
                                                best->detections.front().best.fit.fit)) {
        best = std::move(trial);
      }
    }
    if (best) {
      est.clusters = std::move(best->clusters);
      est.candidates = std::move(best->candidates);
      est.detections = std::move(best->detections);
      est.tracking = best->tracking;
    }
  }
  est.timings.search_ms = MsSince(t);

  est.timings.total_ms = cloud_ms + MsSince(t_start);
  return est;
}

}  // namespace hpose
