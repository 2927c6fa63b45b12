#ifndef HPOSE_BENCH_BENCH_FRAMES_H_
#define HPOSE_BENCH_BENCH_FRAMES_H_

// Shared by the speed benchmarks: the shipped templates, a fixed set of simulated 640x480
// frames with clutter, and the search problems the estimator builds from them.

#include <memory>
#include <string>
#include <vector>

#include "core/common/status.h"
#include "core/scoring/pose_lattice.h"
#include "core/scoring/pose_scorer.h"
#include "core/search/estimator.h"
#include "core/search/pose_search.h"
#include "core/sim/frame_simulator.h"
#include "core/templates/voxel_template.h"

namespace hpose::bench {

// The two templates every benchmark searches, in this order.
inline const std::vector<std::string> kBenchTemplateNames = {"standing", "right_arm_raised"};

// Loads NAME.bt of each of `names` from `dir`.
Result<std::vector<VoxelTemplate>> LoadShippedTemplates(
    const std::string& dir, const std::vector<std::string>& names = kBenchTemplateNames);
// Templates of those joint presets made from the parametric humanoid with the proportions
// `body` (HumanoidDimensions::Variant), as `hpose template generate --body` makes them.
Result<std::vector<VoxelTemplate>> BodyTemplates(
    const std::string& body, const std::vector<std::string>& names = kBenchTemplateNames);

// `count` frame specs: both presets, headings spread over the circle (77 degree strides),
// 0.9-`max_distance_m` away in 12 steps, `clutter` clutter objects, seeds 1..count.
// Deterministic.
std::vector<FrameSpec> BenchFrameSpecs(int count, int clutter = 4, double max_distance_m = 2.0);
// A walk: `count` consecutive frames of one humanoid walking a circle (1.4-`far_m` m away, from
// its nearest point, 2.5 degrees of arc a frame, facing along the path, switching preset every 15
// frames) among the same `clutter` objects.
std::vector<FrameSpec> BenchSequenceSpecs(int count, int clutter = 4, double far_m = 3.0);

// One (cluster, template) search as the estimator sets it up (free-space score, threshold).
struct BenchProblem {
  std::string label;  // "frame 3 cluster 0 standing".
  ClusterVoxels cluster;
  ClusterVoxels free_space;
  std::unique_ptr<PoseScorer> scorer;  // fast scorer over `cluster`.
  const TemplateRotations* rotations = nullptr;
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  int free_space_weight = 1;
  int hit_weight = 1;
  int min_value = 0;  // the score threshold as a value (weighted hits).

  // The problem as the estimator passes it; with_min_value false asks for the optimum.
  SearchProblem Problem(bool with_min_value) const;
};

// Runs cloud, floor and clustering of `frame` with `options` and appends one problem per
// (cluster, template; `rotations` of `templates` in the same order) that passes the estimator's
// height check, exactly as Estimator does.
Status AppendProblems(const SimulatedFrame& frame, const Intrinsics& intrinsics,
                      const EstimatorOptions& options, const std::vector<VoxelTemplate>& templates,
                      const std::vector<std::unique_ptr<TemplateRotations>>& rotations,
                      const std::string& label, std::vector<BenchProblem>* out);

double Median(std::vector<double> v);
// CPU time this thread has used, in ms: on a shared, loaded machine far steadier than wall time
// for single-threaded stages.
double ThreadCpuMs();
// Nearest-rank percentile, p in (0, 100].
double Percentile(std::vector<double> v, double p);

// Prints the vector paths this CPU takes (VectorPathsInUse), for a benchmark's header. False,
// with "<program>: <why>" on stderr, when HPOSE_VECTOR_LEVEL names no level.
bool PrintVectorPaths(const char* program);

}  // namespace hpose::bench

#endif  // HPOSE_BENCH_BENCH_FRAMES_H_
