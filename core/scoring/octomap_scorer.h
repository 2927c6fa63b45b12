#ifndef HPOSE_CORE_SCORING_OCTOMAP_SCORER_H_
#define HPOSE_CORE_SCORING_OCTOMAP_SCORER_H_

#include <memory>

#include "core/scoring/pose_scorer.h"

namespace hpose {

// The reference scorer: the cluster's voxels are the occupied leaves of an OctoMap OcTree at the
// lattice resolution (the paper's octree split down to 16 mm wherever the cluster has points);
// each placed template voxel's key is collected in a key set (so a cell counts once) and looked
// up in the tree. Slow and simple: it defines the score the fast paths must equal.
class OctomapScorer final : public PoseScorer {
 public:
  OctomapScorer(const ClusterVoxels& cluster, const PoseLattice& lattice);
  ~OctomapScorer() override;

  int Hits(const RotatedTemplate& rotated, int ix, int iy) const override;
  int cluster_voxels() const override { return cluster_voxels_; }

 private:
  struct Tree;
  std::unique_ptr<Tree> tree_;
  PoseLattice lattice_;
  int cluster_voxels_ = 0;
};

}  // namespace hpose

#endif  // HPOSE_CORE_SCORING_OCTOMAP_SCORER_H_
