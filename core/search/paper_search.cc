#include <algorithm>
#include <cmath>
#include <vector>

#include "core/search/pose_search.h"

namespace hpose {
namespace {

int RoundSteps(double value, double step) { return static_cast<int>(std::lround(value / step)); }

}  // namespace

SearchResult PaperSearch::Search(const ClusterVoxels& /*cluster*/, const PoseScorer& scorer,
                                 const TemplateRotations& rotations,
                                 const Eigen::Vector2d& centre_ground) const {
  const PoseLattice& lattice = rotations.lattice();
  SearchResult result;
  LatticePose centre{RoundSteps(centre_ground.x(), lattice.step_m()),
                     RoundSteps(centre_ground.y(), lattice.step_m()), 0};
  LatticePose best = centre;
  int best_hits = -1;
  // Best hits seen per theta over every pass, for the runner-up report.
  std::vector<int> theta_hits(lattice.angle_steps, -1);
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
          const int hits = scorer.Hits(rotated, ix, iy);
          ++result.poses_evaluated;
          if (hits > theta_hits[itheta]) {
            theta_hits[itheta] = hits;
            theta_pose[itheta] = LatticePose{ix, iy, itheta};
          }
          if (hits > best_hits) {
            best_hits = hits;
            best = LatticePose{ix, iy, itheta};
          }
        }
      }
    }
    centre = best;
  }

  const int n = scorer.cluster_voxels();
  result.best = best;
  result.pose = ToPose(lattice, best);
  result.hits = std::max(best_hits, 0);
  result.score = n == 0 ? 0.0 : 100.0 * result.hits / n;
  int runner_hits = 0;
  for (int t = 0; t < lattice.angle_steps; ++t) {
    if (theta_hits[t] <= runner_hits) continue;
    const double sep =
        std::abs(AngleDiff(t * lattice.angle_step_rad(), best.itheta * lattice.angle_step_rad()));
    if (sep <= kRunnerUpMinSeparationRad) continue;
    runner_hits = theta_hits[t];
    result.has_runner_up = true;
    result.runner_up_pose = ToPose(lattice, theta_pose[t]);
  }
  result.runner_up_score = n == 0 ? 0.0 : 100.0 * runner_hits / n;
  return result;
}

}  // namespace hpose
