#ifndef HPOSE_CORE_DEPTH_VOXEL_KEY_SET_H_
#define HPOSE_CORE_DEPTH_VOXEL_KEY_SET_H_

#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace hpose {

// The cubes of side leaf_m (aligned at the frame origin, keyed as VoxelDownsample keys them)
// that hold at least one of a set of points, for asking whether any point lies in the cube
// around a place. An open-addressing hash table of the keys: a question costs a key and one or
// two probes of a table of about 4 entries a point.
class VoxelKeySet {
 public:
  // Forgets what it held and takes the cubes of `points` (finite) at `leaf_m` (> 0).
  void Build(const std::vector<Eigen::Vector3f>& points, float leaf_m);
  // Whether a point of the set lies in the cube holding `p` (false when empty).
  bool Contains(const Eigen::Vector3f& p) const;
  size_t size() const { return size_; }

 private:
  size_t Slot(std::uint64_t key) const;

  float inv_leaf_ = 0.0f;
  std::vector<std::uint64_t> slots_;  // kEmpty or a key; a power of two long, 2^bits.
  size_t mask_ = 0;
  int shift_ = 60;  // 64 - bits.
  size_t size_ = 0;
};

}  // namespace hpose

#endif  // HPOSE_CORE_DEPTH_VOXEL_KEY_SET_H_
