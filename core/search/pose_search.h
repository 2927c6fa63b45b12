#ifndef HPOSE_CORE_SEARCH_POSE_SEARCH_H_
#define HPOSE_CORE_SEARCH_POSE_SEARCH_H_

#include <limits>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "core/scoring/pose_lattice.h"
#include "core/scoring/pose_scorer.h"
#include "core/search/runner_up_search.h"
#include "core/search/search_result.h"

namespace hpose {

// One coarse-to-fine pass (SPEC §1 Table 1). Ranges are half-widths around the pass centre.
struct SearchPass {
  double rotation_range_rad = 0.0;
  double rotation_step_rad = 0.0;
  double translation_range_m = 0.0;
  double translation_step_m = 0.0;
};

struct PaperSearchOptions {
  // Table 1: pass 1 +-180 deg / 5 deg, +-128 mm / 16 mm; pass 2 +-4 deg / 2 deg, +-32 mm / 8 mm.
  std::vector<SearchPass> passes = {
      {kPi, DegToRad(5.0), 0.128, 0.016},
      {DegToRad(4.0), DegToRad(2.0), 0.032, 0.008},
  };
};

// Minimum theta separation for the runner-up (front/back ambiguity report).
constexpr double kRunnerUpMinSeparationRad = 30.0 * kPi / 180.0;

// What a search may share with the other searches of the same cluster (made by
// PoseSearch::MakeGrids; opaque here).
struct SearchGrids;

// What a search works on: one template against one cluster.
struct SearchProblem {
  const ClusterVoxels* cluster = nullptr;                   // required.
  const PoseScorer* scorer = nullptr;                       // required; scores `cluster`.
  const TemplateRotations* rotations = nullptr;             // required.
  Eigen::Vector2d centre_ground = Eigen::Vector2d::Zero();  // cluster centroid (x, y), metres.
  // Optional free-space evidence: voxels the sensor saw through (FreeSpaceCells). The value of a
  // pose is then hits - free_space_weight * (free voxels the placed template covers); without
  // it the value is the paper's hits alone.
  const ClusterVoxels* free_space = nullptr;
  int free_space_weight = 1;
  // Weight of a covered cluster voxel: the value is hit_weight * hits - free_space_weight * free
  // hits, so free_space_weight / hit_weight is what one free voxel costs in covered voxels.
  int hit_weight = 1;
  // Values below this do not matter to the caller (e.g. below the humanoid threshold): a search
  // may stop as soon as it has proved that no pose reaches it, and then reports only that
  // bound (SearchResult::below_min_value). The default asks for the optimum whatever it is.
  int min_value = std::numeric_limits<int>::min();
  // Optional, above min_value: the optimum matters only from this value. A search may stop once
  // it has proved that no pose reaches it, as below min_value (and, kept, go on from there when
  // lowered); a runner-up of an optimum it finds is still looked for down to min_value, as
  // without this.
  int optimum_min_value = std::numeric_limits<int>::min();
  // The runner-up (kRunnerUpMinSeparationRad away) matters only within this much value of the
  // optimum: a search may stop looking for it once no other heading can come that near, and then
  // reports none, with an upper bound of its value as when it is below min_value. The default
  // looks down to min_value.
  int runner_up_window = std::numeric_limits<int>::max();
  // Optional: a pose believed good (the previous frame's, when tracking). The exact search
  // evaluates it first and uses its value to order work; the result is the same with or without
  // it (the global optimum is still proved).
  const LatticePose* incumbent = nullptr;
  // Optional: this cluster's grids from MakeGrids (with the same free space), for every template
  // it was made for; the search makes its own without them (same result).
  const SearchGrids* grids = nullptr;
};

// Finds the pose of highest value of one template over one cluster.
class PoseSearch {
 public:
  virtual ~PoseSearch() = default;
  virtual SearchResult Search(const SearchProblem& problem) const = 0;
  // Search's optimum alone, into `result`, and what finding its runner-up takes, for a caller
  // that may not need it (null: `result` holds the runner-up already, or there is none to
  // find). When the search stops below problem.min_value and `stopped` is given, it may keep
  // what it bounded there, to go on to a lower value (left null: search again). By default
  // Search, whole.
  virtual std::unique_ptr<RunnerUpSearch> SearchBest(
      const SearchProblem& problem, SearchResult* result,
      std::unique_ptr<StoppedSearch>* /*stopped*/ = nullptr) const {
    *result = Search(problem);
    return nullptr;
  }
  // How far outside the box of the cluster's voxel cells the search may place the template's
  // origin (metres): what it reads lies within this plus the template's own reach.
  virtual double OriginMargin(const TemplateRotations& rotations) const = 0;
  // What every search of `cluster` (with `free_space`, may be null) with these templates can
  // share, made once, or null when this search shares nothing. Read-only once made: searches
  // on several threads may share it.
  virtual std::shared_ptr<const SearchGrids> MakeGrids(
      const ClusterVoxels& /*cluster*/, const ClusterVoxels* /*free_space*/,
      const std::vector<const TemplateRotations*>& /*rotations*/) const {
    return nullptr;
  }
};

// The paper's two-pass search on the lattice: each pass's steps and ranges are rounded to
// whole lattice steps; pass 1 is centred on the cluster centroid, later passes on the best so
// far.
class PaperSearch final : public PoseSearch {
 public:
  explicit PaperSearch(PaperSearchOptions options = {}) : options_(std::move(options)) {}
  SearchResult Search(const SearchProblem& problem) const override;
  double OriginMargin(const TemplateRotations& rotations) const override;

 private:
  PaperSearchOptions options_;
};

}  // namespace hpose

#endif  // HPOSE_CORE_SEARCH_POSE_SEARCH_H_
