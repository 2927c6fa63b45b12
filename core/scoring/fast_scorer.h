#ifndef HPOSE_CORE_SCORING_FAST_SCORER_H_
#define HPOSE_CORE_SCORING_FAST_SCORER_H_

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "core/scoring/pose_scorer.h"

namespace hpose {

// Same score as OctomapScorer, from a dense occupancy grid over the cluster's bounding box:
// each placed template voxel is one bounds check and one byte lookup; a per-cell stamp makes a
// cell covered by two template voxels count once. Not thread-safe (the stamps are scratch
// space): one scorer per thread.
class FastScorer final : public PoseScorer {
 public:
  FastScorer(const ClusterVoxels& cluster, const PoseLattice& lattice);

  int Hits(const RotatedTemplate& rotated, int ix, int iy) const override;
  int cluster_voxels() const override { return cluster_voxels_; }

  // The grid, for searches that build bounds over it. Cell (x, y, z) is at index
  // ((z - min.z) * size.y + (y - min.y)) * size.x + (x - min.x).
  const Eigen::Vector3i& grid_min() const { return min_; }
  const Eigen::Vector3i& grid_size() const { return size_; }
  bool Occupied(const Eigen::Vector3i& cell) const;

 private:
  PoseLattice lattice_;
  int cluster_voxels_ = 0;
  int shift_ = -1;  // log2(subdivisions) when a power of two, else -1.
  Eigen::Vector3i min_ = Eigen::Vector3i::Zero();
  Eigen::Vector3i size_ = Eigen::Vector3i::Zero();
  std::vector<std::uint8_t> occupied_;
  mutable std::vector<std::uint32_t> stamp_;
  mutable std::uint32_t current_stamp_ = 0;
};

}  // namespace hpose

#endif  // HPOSE_CORE_SCORING_FAST_SCORER_H_
