#include "core/search/exact_search.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <queue>
#include <vector>

#include "core/scoring/column_occupancy.h"

namespace hpose {
namespace {

struct Node {
  int value;   // upper bound, or the exact value when tlevel == level == 0.
  int tlevel;  // theta block of 2^tlevel angle steps starting at itheta.
  int level;   // translation block of 2^level x 2^level lattice steps starting at (a, b).
  int itheta;
  int a;
  int b;
};

// Highest value first; among equal values finer nodes first (exact poses before bounds), then
// a fixed order so results do not depend on heap internals.
struct NodeLess {
  bool operator()(const Node& x, const Node& y) const {
    if (x.value != y.value) return x.value < y.value;
    const int fx = x.tlevel + x.level, fy = y.tlevel + y.level;
    if (fx != fy) return fx > fy;
    if (x.itheta != y.itheta) return x.itheta > y.itheta;
    if (x.a != y.a) return x.a > y.a;
    return x.b > y.b;
  }
};

struct BranchAndBoundResult {
  bool found = false;
  LatticePose best;
  int value = 0;
};

// The value of poses and its bounds: cluster hits (OR pyramid) minus weighted free-space hits
// (AND pyramid, a lower bound of the free hits; only valid for a single rotation, so theta
// blocks bound the free hits by 0).
struct Evaluator {
  const ColumnOccupancy* cluster;
  const ColumnOccupancy* free;  // may be null.
  int weight;

  int Value(const RotatedTemplate& r, int a, int b) const {
    int v = cluster->Hits(r, a, b);
    if (free != nullptr) v -= weight * free->Hits(r, a, b);
    return v;
  }
  int Bound(const RotatedTemplate& r, int a, int b, int level, int tlevel) const {
    int v = cluster->Bound(r, a, b, level);
    if (free != nullptr && tlevel == 0 && level > 0) v -= weight * free->Bound(r, a, b, level);
    return v;
  }
};

// Best-first branch and bound over the allowed thetas and the translation region.
BranchAndBoundResult RunBranchAndBound(const Evaluator& eval, const TemplateRotations& rotations,
                                       const std::vector<bool>& allowed,
                                       const ExactSearch::Region& region, int top_level,
                                       SearchResult* counters) {
  const int steps = static_cast<int>(allowed.size());
  int top_tlevel = TemplateRotations::kThetaLevels - 1;
  while (top_tlevel > 0 && (1 << top_tlevel) > steps) --top_tlevel;
  // Whether any allowed theta lies in [itheta, itheta + 2^tlevel).
  auto any_allowed = [&](int itheta, int tlevel) {
    for (int t = itheta; t < std::min(steps, itheta + (1 << tlevel)); ++t) {
      if (allowed[t]) return true;
    }
    return false;
  };
  std::priority_queue<Node, std::vector<Node>, NodeLess> queue;
  auto push = [&](int tlevel, int itheta, int level, int a, int b) {
    if (a > region.ix_max || b > region.iy_max || itheta >= steps) return;
    if (!any_allowed(itheta, tlevel)) return;
    if (tlevel == 0 && level == 0) {
      ++counters->poses_evaluated;
      queue.push({eval.Value(rotations.Get(itheta), a, b), 0, 0, itheta, a, b});
    } else {
      ++counters->bounds_evaluated;
      const RotatedTemplate& rot = rotations.GetBlock(tlevel, itheta);
      queue.push({eval.Bound(rot, a, b, level, tlevel), tlevel, level, itheta, a, b});
    }
  };
  const int block = 1 << top_level;
  for (int itheta = 0; itheta < steps; itheta += 1 << top_tlevel) {
    for (int a = region.ix_min; a <= region.ix_max; a += block) {
      for (int b = region.iy_min; b <= region.iy_max; b += block) {
        push(top_tlevel, itheta, top_level, a, b);
      }
    }
  }
  BranchAndBoundResult out;
  while (!queue.empty()) {
    const Node n = queue.top();
    queue.pop();
    if (n.tlevel == 0 && n.level == 0) {
      out.found = true;
      out.best = LatticePose{n.a, n.b, n.itheta};
      out.value = n.value;
      return out;
    }
    // Split the rotation while it sweeps further than the translation block spans.
    if (n.tlevel > 0 && (n.level == 0 || n.tlevel + 2 >= n.level)) {
      const int half = 1 << (n.tlevel - 1);
      push(n.tlevel - 1, n.itheta, n.level, n.a, n.b);
      push(n.tlevel - 1, n.itheta + half, n.level, n.a, n.b);
    } else {
      const int half = 1 << (n.level - 1);
      for (int da : {0, half}) {
        for (int db : {0, half}) push(n.tlevel, n.itheta, n.level - 1, n.a + da, n.b + db);
      }
    }
  }
  return out;
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

SearchResult ExactSearch::Search(const SearchProblem& problem) const {
  SearchResult result;
  const ClusterVoxels& cluster = *problem.cluster;
  const TemplateRotations& rotations = *problem.rotations;
  const PoseLattice& lattice = rotations.lattice();
  const Region region = TranslationRegion(cluster, rotations);
  const int n = problem.scorer->cluster_voxels();
  if (region.ix_max < region.ix_min || n == 0) return result;

  const int span = std::max(region.ix_max - region.ix_min, region.iy_max - region.iy_min) + 1;
  int top = 0;
  while (top < options_.max_level && (1 << top) < span) ++top;
  const RotatedTemplate& r0 = rotations.Get(0);
  const ColumnOccupancy occ(cluster, lattice, r0.z_base, r0.z_words, top);
  std::unique_ptr<ColumnOccupancy> free;
  if (problem.free_space != nullptr) {
    free = std::make_unique<ColumnOccupancy>(*problem.free_space, lattice, r0.z_base, r0.z_words,
                                             top, ColumnOccupancy::Filter::kMin);
  }
  const Evaluator eval{&occ, free.get(), problem.free_space_weight};

  const std::vector<bool> all(lattice.angle_steps, true);
  const BranchAndBoundResult best = RunBranchAndBound(eval, rotations, all, region, top, &result);
  if (!best.found) return result;
  const RotatedTemplate& rb = rotations.Get(best.best.itheta);
  result.best = best.best;
  result.pose = ToPose(lattice, best.best);
  result.value = best.value;
  result.hits = occ.Hits(rb, best.best.ix, best.best.iy);
  result.free_hits = free != nullptr ? free->Hits(rb, best.best.ix, best.best.iy) : 0;
  result.score = 100.0 * best.value / n;
  result.coverage = 100.0 * result.hits / n;

  std::vector<bool> others(lattice.angle_steps, false);
  for (int t = 0; t < lattice.angle_steps; ++t) {
    const double sep = std::abs(
        AngleDiff(t * lattice.angle_step_rad(), best.best.itheta * lattice.angle_step_rad()));
    others[t] = sep > kRunnerUpMinSeparationRad;
  }
  const BranchAndBoundResult runner =
      RunBranchAndBound(eval, rotations, others, region, top, &result);
  if (runner.found) {
    result.has_runner_up = true;
    result.runner_up_pose = ToPose(lattice, runner.best);
    result.runner_up_score = 100.0 * runner.value / n;
  }
  return result;
}

}  // namespace hpose
