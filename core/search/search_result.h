#ifndef HPOSE_CORE_SEARCH_SEARCH_RESULT_H_
#define HPOSE_CORE_SEARCH_SEARCH_RESULT_H_

#include <cstdint>

#include "core/common/pose2d.h"
#include "core/scoring/pose_lattice.h"

namespace hpose {

// The outcome of searching one template against one cluster.
struct SearchResult {
  LatticePose best;
  Pose2D pose;            // ground frame.
  int hits = 0;           // cluster voxels covered at the best pose.
  int free_hits = 0;      // free-space voxels covered there (0 without free space).
  int value = 0;          // hits - weight * free_hits: what the search maximised.
  double score = 0.0;     // 100 * value / cluster voxels (the paper's score without free space).
  double coverage = 0.0;  // 100 * hits / cluster voxels: the paper's score.
  // The best pose whose theta differs from the best by more than 30 degrees (front/back
  // ambiguity). has_runner_up is false when there is none or, with a min_value or a
  // runner_up_window (SearchProblem), when none reaches it; runner_up_score then holds an upper
  // bound of their scores.
  bool has_runner_up = false;
  Pose2D runner_up_pose;
  double runner_up_score = 0.0;
  // True when the search proved that no pose reaches SearchProblem::min_value and stopped:
  // then `value_upper_bound` (and score_upper_bound) bound every pose's value, and best, pose,
  // value, hits and score are those of the best pose it evaluated exactly (a real pose, not
  // proven the optimum); the runner-up is not searched.
  bool below_min_value = false;
  int value_upper_bound = 0;
  double score_upper_bound = 0.0;
  // SearchProblem::incumbent lay in the searched region and was evaluated: its value.
  bool incumbent_used = false;
  int incumbent_value = 0;
  std::int64_t poses_evaluated = 0;   // full score evaluations (bounds not counted).
  std::int64_t bounds_evaluated = 0;  // upper-bound evaluations (branch and bound only).
};

}  // namespace hpose

#endif  // HPOSE_CORE_SEARCH_SEARCH_RESULT_H_
