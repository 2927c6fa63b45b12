#include "core/search/exact_search.h"

#include <algorithm>
#include <cmath>
#include <queue>
#include <vector>

#include "core/scoring/column_occupancy.h"

namespace hpose {
namespace {

struct Node {
  int value;  // upper bound, or the exact hits when level == 0.
  int level;  // block of 2^level x 2^level translations; 0 = one pose, value exact.
  int itheta;
  int a;
  int b;
};

// Highest value first; among equal values exact poses first, then a fixed order so results do
// not depend on heap internals.
struct NodeLess {
  bool operator()(const Node& x, const Node& y) const {
    if (x.value != y.value) return x.value < y.value;
    if (x.level != y.level) return x.level > y.level;
    if (x.itheta != y.itheta) return x.itheta > y.itheta;
    if (x.a != y.a) return x.a > y.a;
    return x.b > y.b;
  }
};

struct BranchAndBoundResult {
  bool found = false;
  LatticePose best;
  int hits = 0;
};

// Best-first branch and bound over the thetas in `thetas` and the translation region.
BranchAndBoundResult RunBranchAndBound(const ColumnOccupancy& occ,
                                       const TemplateRotations& rotations,
                                       const std::vector<int>& thetas,
                                       const ExactSearch::Region& region, int top_level,
                                       SearchResult* counters) {
  std::priority_queue<Node, std::vector<Node>, NodeLess> queue;
  const int block = 1 << top_level;
  auto push_block = [&](int itheta, int a, int b, int level) {
    if (a > region.ix_max || b > region.iy_max) return;
    const RotatedTemplate& rot = rotations.Get(itheta);
    if (level == 0) {
      ++counters->poses_evaluated;
      queue.push({occ.Hits(rot, a, b), 0, itheta, a, b});
    } else {
      ++counters->bounds_evaluated;
      const int bound = occ.Bound(rot, a, b, level);
      if (bound > 0) queue.push({bound, level, itheta, a, b});
    }
  };
  for (int itheta : thetas) {
    for (int a = region.ix_min; a <= region.ix_max; a += block) {
      for (int b = region.iy_min; b <= region.iy_max; b += block) {
        push_block(itheta, a, b, top_level);
      }
    }
  }
  BranchAndBoundResult out;
  while (!queue.empty()) {
    const Node n = queue.top();
    queue.pop();
    if (n.level == 0) {
      out.found = true;
      out.best = LatticePose{n.a, n.b, n.itheta};
      out.hits = n.value;
      return out;
    }
    const int half = 1 << (n.level - 1);
    for (int da : {0, half}) {
      for (int db : {0, half}) push_block(n.itheta, n.a + da, n.b + db, n.level - 1);
    }
  }
  return out;  // nothing overlaps the cluster at all.
}

}  // namespace

ExactSearch::Region ExactSearch::TranslationRegion(const ClusterVoxels& cluster,
                                                   const TemplateRotations& rotations) const {
  Region r;
  if (cluster.cells.empty()) return r;
  const PoseLattice& lattice = rotations.lattice();
  int x_lo = cluster.cells.front().x(), x_hi = x_lo;
  int y_lo = cluster.cells.front().y(), y_hi = y_lo;
  for (const Eigen::Vector3i& c : cluster.cells) {
    x_lo = std::min(x_lo, c.x());
    x_hi = std::max(x_hi, c.x());
    y_lo = std::min(y_lo, c.y());
    y_hi = std::max(y_hi, c.y());
  }
  double margin = options_.margin_m;
  if (margin < 0.0) {
    // Horizontal radius of the template from its rotation at theta = 0.
    const RotatedTemplate& r0 = rotations.Get(0);
    const double q_to_m = lattice.resolution_m / lattice.subdivisions;
    double radius = 0.0;
    for (const Eigen::Vector3i& q : r0.sub_cells) {
      radius = std::max(radius, std::hypot((q.x() + 1.0) * q_to_m, (q.y() + 1.0) * q_to_m));
      radius = std::max(radius, std::hypot(q.x() * q_to_m, q.y() * q_to_m));
    }
    margin = radius + lattice.resolution_m;
  }
  const double res = lattice.resolution_m;
  const double step = lattice.step_m();
  r.ix_min = static_cast<int>(std::floor((x_lo * res - margin) / step));
  r.ix_max = static_cast<int>(std::ceil(((x_hi + 1) * res + margin) / step));
  r.iy_min = static_cast<int>(std::floor((y_lo * res - margin) / step));
  r.iy_max = static_cast<int>(std::ceil(((y_hi + 1) * res + margin) / step));
  return r;
}

SearchResult ExactSearch::Search(const ClusterVoxels& cluster, const PoseScorer& scorer,
                                 const TemplateRotations& rotations,
                                 const Eigen::Vector2d& /*centre_ground*/) const {
  SearchResult result;
  const PoseLattice& lattice = rotations.lattice();
  const Region region = TranslationRegion(cluster, rotations);
  const int n = scorer.cluster_voxels();
  if (region.ix_max < region.ix_min || n == 0) return result;

  const int span = std::max(region.ix_max - region.ix_min, region.iy_max - region.iy_min) + 1;
  int top = 0;
  while (top < options_.max_level && (1 << top) < span) ++top;
  const RotatedTemplate& r0 = rotations.Get(0);
  const ColumnOccupancy occ(cluster, lattice, r0.z_base, r0.z_words, top);

  std::vector<int> thetas(lattice.angle_steps);
  for (int t = 0; t < lattice.angle_steps; ++t) thetas[t] = t;
  const BranchAndBoundResult best = RunBranchAndBound(occ, rotations, thetas, region, top, &result);
  if (!best.found) return result;
  result.best = best.best;
  result.pose = ToPose(lattice, best.best);
  result.hits = best.hits;
  result.score = 100.0 * best.hits / n;

  std::vector<int> others;
  for (int t = 0; t < lattice.angle_steps; ++t) {
    const double sep = std::abs(
        AngleDiff(t * lattice.angle_step_rad(), best.best.itheta * lattice.angle_step_rad()));
    if (sep > kRunnerUpMinSeparationRad) others.push_back(t);
  }
  const BranchAndBoundResult runner =
      RunBranchAndBound(occ, rotations, others, region, top, &result);
  if (runner.found && runner.hits > 0) {
    result.has_runner_up = true;
    result.runner_up_pose = ToPose(lattice, runner.best);
    result.runner_up_score = 100.0 * runner.hits / n;
  }
  return result;
}

}  // namespace hpose
