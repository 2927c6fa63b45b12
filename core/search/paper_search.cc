#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "core/scoring/fast_scorer.h"
#include "core/search/pose_search.h"

namespace hpose {
namespace {

int RoundSteps(double value, double step) { return static_cast<int>(std::lround(value / step)); }

}  // namespace

double PaperSearch::OriginMargin(const TemplateRotations& rotations) const {
  // Pass 1 is centred on the centroid (within the cluster's box, rounded to a step); each pass
  // moves the centre by at most its translation range.
  const double step = rotations.lattice().step_m();
  double margin = step;
  for (const SearchPass& pass : options_.passes) {
    const int t_step = std::max(1, RoundSteps(pass.translation_step_m, step));
    margin += RoundSteps(pass.translation_range_m, step) / t_step * t_step * step;
  }
  return margin;
}

SearchResult PaperSearch::Search(const SearchProblem& problem) const {
  const PoseScorer& scorer = *problem.scorer;
  const TemplateRotations& rotations = *problem.rotations;
  const PoseLattice& lattice = rotations.lattice();
  std::unique_ptr<FastScorer> free_scorer;
  if (problem.free_space != nullptr) {
    free_scorer = std::make_unique<FastScorer>(*problem.free_space, lattice);
  }
  struct Value {
    int value = 0, hits = 0, free = 0;
  };
  auto evaluate = [&](const RotatedTemplate& r, int ix, int iy) {
    Value v;
    v.hits = scorer.Hits(r, ix, iy);
    v.free = free_scorer != nullptr ? free_scorer->Hits(r, ix, iy) : 0;
    v.value = problem.hit_weight * v.hits - problem.free_space_weight * v.free;
    return v;
  };

  SearchResult result;
  LatticePose centre{RoundSteps(problem.centre_ground.x(), lattice.step_m()),
                     RoundSteps(problem.centre_ground.y(), lattice.step_m()), 0};
  LatticePose best = centre;
  Value best_value;
  bool have_best = false;
  // Best value seen per theta over every pass, for the runner-up report.
  std::vector<bool> theta_seen(lattice.angle_steps, false);
  std::vector<Value> theta_value(lattice.angle_steps);
  std::vector<LatticePose> theta_pose(lattice.angle_steps);

  for (const SearchPass& pass : options_.passes) {
    const int rot_step = std::max(1, RoundSteps(pass.rotation_step_rad, lattice.angle_step_rad()));
    const int rot_half = RoundSteps(pass.rotation_range_rad, lattice.angle_step_rad());
    const int t_step = std::max(1, RoundSteps(pass.translation_step_m, lattice.step_m()));
    const int t_half = RoundSteps(pass.translation_range_m, lattice.step_m()) / t_step * t_step;

    std::vector<int> thetas;
    if (2 * rot_half >= lattice.angle_steps) {
      for (int d = 0; d < lattice.angle_steps; d += rot_step) {
        thetas.push_back(WrapAngleIndex(lattice, centre.itheta + d));
      }
    } else {
      const int half = rot_half / rot_step * rot_step;
      for (int d = -half; d <= half; d += rot_step) {
        thetas.push_back(WrapAngleIndex(lattice, centre.itheta + d));
      }
    }
    for (int itheta : thetas) {
      const RotatedTemplate& rotated = rotations.Get(itheta);
      for (int dx = -t_half; dx <= t_half; dx += t_step) {
        for (int dy = -t_half; dy <= t_half; dy += t_step) {
          const int ix = centre.ix + dx;
          const int iy = centre.iy + dy;
          const Value v = evaluate(rotated, ix, iy);
          ++result.poses_evaluated;
          if (!theta_seen[itheta] || v.value > theta_value[itheta].value) {
            theta_seen[itheta] = true;
            theta_value[itheta] = v;
            theta_pose[itheta] = LatticePose{ix, iy, itheta};
          }
          if (!have_best || v.value > best_value.value) {
            have_best = true;
            best_value = v;
            best = LatticePose{ix, iy, itheta};
          }
        }
      }
    }
    centre = best;
  }

  const int n = scorer.cluster_voxels();
  const int n_weighted = n * problem.hit_weight;
  if (!have_best || n == 0) return result;
  result.best = best;
  result.pose = ToPose(lattice, best);
  result.hits = best_value.hits;
  result.free_hits = best_value.free;
  result.value = best_value.value;
  result.score = 100.0 * best_value.value / n_weighted;
  result.coverage = 100.0 * best_value.hits / n;
  for (int t = 0; t < lattice.angle_steps; ++t) {
    if (!theta_seen[t]) continue;
    const double sep =
        std::abs(AngleDiff(t * lattice.angle_step_rad(), best.itheta * lattice.angle_step_rad()));
    if (sep <= kRunnerUpMinSeparationRad) continue;
    if (result.has_runner_up &&
        theta_value[t].value * 100.0 / n_weighted <= result.runner_up_score) {
      continue;
    }
    result.has_runner_up = true;
    result.runner_up_pose = ToPose(lattice, theta_pose[t]);
    result.runner_up_score = 100.0 * theta_value[t].value / n_weighted;
  }
  return result;
}

}  // namespace hpose
