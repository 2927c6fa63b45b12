#include "core/scoring/pose_scorer.h"

#include <algorithm>
#include <tuple>

#include "core/scoring/fast_scorer.h"
#include "core/scoring/octomap_scorer.h"

namespace hpose {

ClusterVoxels VoxeliseCluster(const std::vector<Eigen::Vector3f>& points_ground,
                              double resolution_m) {
  ClusterVoxels out;
  out.resolution_m = resolution_m;
  out.cells.reserve(points_ground.size());
  for (const Eigen::Vector3f& p : points_ground) {
    if (p.allFinite()) out.cells.push_back(CellOf(p, resolution_m));
  }
  auto less = [](const Eigen::Vector3i& a, const Eigen::Vector3i& b) {
    return std::tie(a.x(), a.y(), a.z()) < std::tie(b.x(), b.y(), b.z());
  };
  std::sort(out.cells.begin(), out.cells.end(), less);
  out.cells.erase(std::unique(out.cells.begin(), out.cells.end()), out.cells.end());
  return out;
}

const char* ScorerKindName(ScorerKind kind) {
  switch (kind) {
    case ScorerKind::kOctomapReference:
      return "octomap";
    case ScorerKind::kFast:
      return "fast";
  }
  return "?";
}

std::unique_ptr<PoseScorer> MakePoseScorer(ScorerKind kind, const ClusterVoxels& cluster,
                                           const PoseLattice& lattice) {
  switch (kind) {
    case ScorerKind::kOctomapReference:
      return std::make_unique<OctomapScorer>(cluster, lattice);
    case ScorerKind::kFast:
      return std::make_unique<FastScorer>(cluster, lattice);
  }
  return nullptr;
}

}  // namespace hpose
