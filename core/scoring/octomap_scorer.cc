#include "core/scoring/octomap_scorer.h"

#include <octomap/OcTree.h>

namespace hpose {

struct OctomapScorer::Tree {
  explicit Tree(double resolution) : octree(resolution) {}
  octomap::OcTree octree;

  // OctoMap key of an integer cell: the key of the cell's centre coordinate.
  octomap::OcTreeKey KeyOf(const Eigen::Vector3i& cell) const {
    const double res = octree.getResolution();
    return octree.coordToKey((cell.x() + 0.5) * res, (cell.y() + 0.5) * res,
                             (cell.z() + 0.5) * res);
  }
};

OctomapScorer::OctomapScorer(const ClusterVoxels& cluster, const PoseLattice& lattice)
    : tree_(std::make_unique<Tree>(lattice.resolution_m)),
      lattice_(lattice),
      cluster_voxels_(static_cast<int>(cluster.cells.size())) {
  for (const Eigen::Vector3i& cell : cluster.cells) {
    tree_->octree.updateNode(tree_->KeyOf(cell), true);
  }
}

OctomapScorer::~OctomapScorer() = default;

int OctomapScorer::Hits(const RotatedTemplate& rotated, int ix, int iy) const {
  octomap::KeySet placed;
  ForEachPlacedVoxel(rotated, [&](const Eigen::Vector3i& sub) {
    placed.insert(tree_->KeyOf(PlacedCell(sub, ix, iy, lattice_.subdivisions)));
  });
  int hits = 0;
  for (const octomap::OcTreeKey& key : placed) {
    const octomap::OcTreeNode* node = tree_->octree.search(key);
    if (node != nullptr && tree_->octree.isNodeOccupied(node)) ++hits;
  }
  return hits;
}

}  // namespace hpose
