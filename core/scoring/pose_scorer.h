#ifndef HPOSE_CORE_SCORING_POSE_SCORER_H_
#define HPOSE_CORE_SCORING_POSE_SCORER_H_

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/scoring/pose_lattice.h"

namespace hpose {

// The distinct voxel cells (CellOf) a cluster occupies, sorted.
struct ClusterVoxels {
  double resolution_m = 0.016;
  std::vector<Eigen::Vector3i> cells;
};

// With `two_points_a_cell`, only the cells that two or more of the points fall in.
ClusterVoxels VoxeliseCluster(const std::vector<Eigen::Vector3f>& points_ground,
                              double resolution_m, bool two_points_a_cell = false);

// Scores a template placed on the lattice against one cluster (SPEC §1):
//   score = 100 * (cluster voxels the placed template also occupies) / (cluster voxels).
class PoseScorer {
 public:
  virtual ~PoseScorer() = default;

  // Number of distinct cluster voxels occupied by the template rotated by `rotated.itheta` and
  // translated by (ix, iy) lattice steps.
  virtual int Hits(const RotatedTemplate& rotated, int ix, int iy) const = 0;
  virtual int cluster_voxels() const = 0;

  double Score(const RotatedTemplate& rotated, int ix, int iy) const {
    const int n = cluster_voxels();
    return n == 0 ? 0.0 : 100.0 * Hits(rotated, ix, iy) / n;
  }
};

enum class ScorerKind { kOctomapReference, kFast };

const char* ScorerKindName(ScorerKind kind);

// Builds a scorer for one cluster. kOctomapReference: the cluster's voxels in an OctoMap
// OcTree, each placed template voxel looked up in it (the reference). kFast: see fast_scorer.h.
std::unique_ptr<PoseScorer> MakePoseScorer(ScorerKind kind, const ClusterVoxels& cluster,
                                           const PoseLattice& lattice);

}  // namespace hpose

#endif  // HPOSE_CORE_SCORING_POSE_SCORER_H_
