#include "core/search/estimator.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <set>

#include "core/depth/cloud_validation.h"
#include "core/search/exact_search.h"

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

const char* SearchKindName(SearchKind kind) {
  switch (kind) {
    case SearchKind::kPaper:
      return "paper";
    case SearchKind::kExact:
      return "exact";
  }
  return "?";
}

const char* ScoreKindName(ScoreKind kind) {
  switch (kind) {
    case ScoreKind::kPaper:
      return "paper";
    case ScoreKind::kFreeSpace:
      return "free-space";
  }
  return "?";
}

Result<ScoreKind> ParseScoreKind(const std::string& name) {
  if (name == "paper") return ScoreKind::kPaper;
  if (name == "free-space") return ScoreKind::kFreeSpace;
  return MakeError(ErrorCode::kInvalidArgument,
                   "unknown score '" + name + "' (expected 'paper' or 'free-space')");
}

Result<SearchKind> ParseSearchKind(const std::string& name) {
  if (name == "paper") return SearchKind::kPaper;
  if (name == "exact") return SearchKind::kExact;
  return MakeError(ErrorCode::kInvalidArgument,
                   "unknown search '" + name + "' (expected 'paper' or 'exact')");
}

EstimatorOptions DefaultEstimatorOptions() { return EstimatorOptions{}; }

Estimator::Estimator(EstimatorOptions options, std::vector<VoxelTemplate> templates)
    : options_(std::move(options)), templates_(std::move(templates)) {
  rotations_.reserve(templates_.size());
  for (const VoxelTemplate& t : templates_) {
    rotations_.push_back(std::make_unique<TemplateRotations>(t, options_.lattice));
    silhouette_widths_.push_back(SilhouetteWidths(t, options_.clusters.min_height_above_floor_m));
  }
  search_ = MakeSearch(options_);
}

Estimator::~Estimator() = default;

Result<std::unique_ptr<Estimator>> Estimator::Create(EstimatorOptions options,
                                                     std::vector<VoxelTemplate> templates) {
  if (templates.empty()) {
    return MakeError(ErrorCode::kInvalidArgument, "no templates given (at least one is needed)");
  }
  Status st = options.lattice.Validate();
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
    if (std::abs(t.resolution_m - options.lattice.resolution_m) > 1e-9) {
      return MakeError(ErrorCode::kInvalidArgument,
                       "template '" + t.name + "' has resolution " +
                           std::to_string(t.resolution_m) + " m but the search uses " +
                           std::to_string(options.lattice.resolution_m) + " m");
    }
  }
  if (!(options.score_threshold >= 0.0 && options.score_threshold <= 100.0)) {
    return MakeError(ErrorCode::kInvalidArgument, "score_threshold must be within [0, 100]");
  }
  std::unique_ptr<Estimator> e(new Estimator(std::move(options), std::move(templates)));
  if (e->search_ == nullptr) {
    return MakeError(ErrorCode::kInvalidArgument, std::string("search '") +
                                                      SearchKindName(e->options_.search) +
                                                      "' is not available in this build");
  }
  return e;
}

Result<Estimate> Estimator::EstimateDepth(const DepthImage& depth,
                                          const Intrinsics& intrinsics) const {
  const Clock::time_point t0 = Clock::now();
  Result<PointCloud> cloud = DepthToCloud(depth, intrinsics, options_.cloud);
  if (!cloud.ok()) return cloud.error();
  return Run(*cloud, MsSince(t0));
}

Result<Estimate> Estimator::EstimateCloud(const PointCloud& cloud_sensor) const {
  return Run(cloud_sensor, 0.0);
}

Result<Estimate> Estimator::Run(const PointCloud& cloud, double cloud_ms) const {
  const Clock::time_point t_start = Clock::now();
  Estimate est;
  est.timings.cloud_ms = cloud_ms;
  const Status valid = ValidateCloud(cloud);  // finite and bounded before PCL sees it.
  if (!valid.ok()) return valid.error();
  if (cloud.empty()) {
    return MakeError(ErrorCode::kInvalidArgument, "the point cloud is empty (no valid depth)");
  }
  int finite = 0;
  for (const Eigen::Vector3f& p : cloud.points) finite += p.allFinite() ? 1 : 0;
  if (finite == 0) {
    return MakeError(ErrorCode::kInvalidArgument, "the point cloud has no finite points (all " +
                                                      std::to_string(cloud.size()) +
                                                      " are NaN or infinite)");
  }
  est.cloud_points = finite;

  Clock::time_point t = Clock::now();
  if (options_.use_fixed_floor) {
    est.floor = options_.fixed_floor;
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

  t = Clock::now();
  const bool use_free_space = options_.score == ScoreKind::kFreeSpace;
  RangeImage range;
  Eigen::Isometry3d sensor_from_ground = est.floor.ground_from_sensor.inverse();
  double reach = 0.0;  // how far any template reaches from its origin, plus a voxel.
  int top_cell = 0;    // highest template voxel cell.
  if (use_free_space) {
    range = RangeImage::FromCloud(cloud, options_.range_image_focal_px);
    for (const VoxelTemplate& tpl : templates_) {
      for (const Eigen::Vector3f& v : tpl.voxels) {
        reach = std::max(reach, static_cast<double>(v.head<2>().norm()));
        top_cell = std::max(top_cell, CellOf(v, options_.lattice.resolution_m).z());
      }
    }
    reach += 2.0 * options_.lattice.resolution_m;
  }
  for (size_t i = 0; i < clusters->size(); ++i) {
    const Cluster& c = (*clusters)[i];
    ClusterSummary summary;
    summary.index = static_cast<int>(i);
    summary.points = static_cast<int>(c.points.size());
    summary.centroid = c.centroid;
    summary.min = c.min;
    summary.max = c.max;

    std::unique_ptr<PoseScorer> scorer;
    ClusterVoxels voxels;
    ClusterVoxels free;
    const double width = ApparentWidth(c);
    for (size_t j = 0; j < templates_.size(); ++j) {
      const TemplateRotations& rot = *rotations_[j];
      if (options_.max_height_ratio_error >= 0.0) {
        const double ratio = c.height() / rot.height_m();
        if (std::abs(ratio - 1.0) > options_.max_height_ratio_error) continue;
      }
      const auto [narrow, wide] = silhouette_widths_[j];
      if (options_.min_width_ratio >= 0.0 && width < options_.min_width_ratio * narrow) continue;
      if (options_.max_width_ratio >= 0.0 && width > options_.max_width_ratio * wide) continue;
      if (scorer == nullptr) {
        const double res = options_.lattice.resolution_m;
        voxels = VoxeliseCluster(c.points, res);
        scorer = MakePoseScorer(options_.scorer, voxels, options_.lattice);
        if (use_free_space) {
          // Wherever a template placed in the search region can reach (the search region grows
          // the cluster by one template reach, the template reaches one more).
          const Eigen::Vector3f lo(c.min.x() - 2 * reach, c.min.y() - 2 * reach, 0.0f);
          const Eigen::Vector3f hi(c.max.x() + 2 * reach, c.max.y() + 2 * reach, 0.0f);
          Eigen::Vector3i cell_lo = CellOf(lo, res), cell_hi = CellOf(hi, res);
          cell_lo.z() = 0;
          cell_hi.z() = top_cell;
          free =
              FreeSpaceCells(range, sensor_from_ground, cell_lo, cell_hi, res, options_.free_space);
        }
      }
      SearchProblem problem;
      problem.cluster = &voxels;
      problem.scorer = scorer.get();
      problem.rotations = &rot;
      problem.centre_ground = c.centroid.head<2>().cast<double>();
      problem.free_space = use_free_space ? &free : nullptr;
      problem.free_space_weight = options_.free_space_weight;
      problem.hit_weight = options_.hit_weight;
      if (options_.stop_below_threshold) {
        problem.min_value = static_cast<int>(std::ceil(
            options_.score_threshold * options_.hit_weight * scorer->cluster_voxels() / 100.0 -
            1e-9));
      }
      const SearchResult r = search_->Search(problem);
      Candidate cand;
      cand.template_name = rot.name();
      cand.cluster_index = summary.index;
      cand.pose = r.pose;
      cand.score = r.score;
      cand.coverage = r.coverage;
      cand.score_is_upper_bound = r.below_min_value;
      cand.free_space_hits = r.free_hits;
      cand.hits = r.hits;
      cand.cluster_voxels = scorer->cluster_voxels();
      cand.has_runner_up = r.has_runner_up;
      cand.runner_up_pose = r.runner_up_pose;
      cand.runner_up_score = r.runner_up_score;
      cand.poses_evaluated = r.poses_evaluated;
      cand.bounds_evaluated = r.bounds_evaluated;
      est.candidates.push_back(cand);
      summary.searched = true;
    }
    est.clusters.push_back(summary);
  }
  est.timings.search_ms = MsSince(t);

  std::stable_sort(est.candidates.begin(), est.candidates.end(),
                   [](const Candidate& a, const Candidate& b) { return a.score > b.score; });
  // Candidates are sorted, so the first seen per cluster is its best template.
  std::map<int, size_t> detection_of_cluster;
  for (const Candidate& cand : est.candidates) {
    auto it = detection_of_cluster.find(cand.cluster_index);
    if (it == detection_of_cluster.end()) {
      Detection d;
      d.best = cand;
      d.template_margin = cand.score;
      d.is_humanoid = cand.score >= options_.score_threshold;
      detection_of_cluster[cand.cluster_index] = est.detections.size();
      est.detections.push_back(d);
    } else {
      Detection& d = est.detections[it->second];
      if (d.second_template.empty()) {
        d.second_template = cand.template_name;
        d.template_margin = d.best.score - cand.score;
      }
    }
  }
  est.timings.total_ms = cloud_ms + MsSince(t_start);
  return est;
}

}  // namespace hpose
