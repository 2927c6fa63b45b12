#ifndef HPOSE_CORE_SEARCH_ESTIMATE_H_
#define HPOSE_CORE_SEARCH_ESTIMATE_H_

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/common/pose2d.h"
#include "core/depth/floor_estimate.h"

namespace hpose {

// One template's best match on one cluster.
struct Candidate {
  std::string template_name;
  int cluster_index = -1;
  Pose2D pose;              // robot frame in the ground frame.
  double score = 0.0;       // what the search maximised, 100 * value / cluster voxels (<= 100).
  double coverage = 0.0;    // the paper's score: 100 * cluster voxels covered / cluster voxels.
  int free_space_hits = 0;  // template voxels in observed free space at the pose.
  // True when the search only proved the score below the threshold: `score` is then an upper
  // bound of every pose's score and the pose is not set.
  bool score_is_upper_bound = false;
  int hits = 0;
  int cluster_voxels = 0;
  bool has_runner_up = false;  // best pose with theta more than 30 deg away.
  Pose2D runner_up_pose;
  double runner_up_score = 0.0;
  std::int64_t poses_evaluated = 0;   // exact score evaluations.
  std::int64_t bounds_evaluated = 0;  // branch-and-bound upper bounds (exact search only).
};

// A cluster's verdict: its best template, and how far ahead of the next template it is.
struct Detection {
  Candidate best;
  std::string second_template;   // empty with one template.
  double template_margin = 0.0;  // best.score - second template's score on this cluster.
  bool is_humanoid = false;      // best.score >= the score threshold.
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
  double search_ms = 0.0;
  double total_ms = 0.0;
};

// Everything one frame produced.
struct Estimate {
  FloorEstimate floor;
  int cloud_points = 0;
  std::vector<ClusterSummary> clusters;
  std::vector<Candidate> candidates;  // every (cluster, template), best score first.
  std::vector<Detection> detections;  // one per searched cluster, best score first.
  StageTimings timings;

  // Detections that pass the score threshold (is_humanoid), best first.
  std::vector<Detection> Humanoids() const;
};

}  // namespace hpose

#endif  // HPOSE_CORE_SEARCH_ESTIMATE_H_
