#include "core/depth/voxel_downsample.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>

namespace hpose {
namespace {

// 21 bits per axis: +-2^20 voxels, i.e. +-8 km at 8 mm; coordinates beyond are clamped.
constexpr std::int64_t kAxisLimit = (1 << 20) - 1;
constexpr std::uint64_t kEmpty = ~std::uint64_t{0};

std::uint64_t PackKey(const Eigen::Vector3f& p, float inv_leaf) {
  std::uint64_t key = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const float cell = std::floor(p[axis] * inv_leaf);
    const float limit = static_cast<float>(kAxisLimit);
    const std::int64_t clamped = static_cast<std::int64_t>(std::clamp(cell, -limit, limit));
    key = (key << 21) | static_cast<std::uint64_t>(clamped + kAxisLimit);
  }
  return key;
}

std::uint64_t Mix(std::uint64_t key) {
  key ^= key >> 33;
  key *= 0xff51afd7ed558ccdULL;
  key ^= key >> 33;
  return key;
}

}  // namespace

void VoxelDownsample(const std::vector<Eigen::Vector3f>& points, float leaf_m,
                     std::vector<Eigen::Vector3f>* centroids, std::vector<int>* voxel_of_point) {
  assert(leaf_m > 0.0f);
  assert(centroids != nullptr);
  centroids->clear();
  if (voxel_of_point != nullptr) voxel_of_point->resize(points.size());
  if (points.empty()) return;

  size_t capacity = 16;
  while (capacity < 2 * points.size()) capacity <<= 1;
  const size_t mask = capacity - 1;
  struct Slot {
    std::uint64_t key;
    int voxel;
  };
  std::vector<Slot> table(capacity, Slot{kEmpty, -1});
  std::vector<int> counts;
  counts.reserve(points.size() / 4 + 16);
  centroids->reserve(points.size() / 4 + 16);

  const float inv_leaf = 1.0f / leaf_m;
  // Depth-camera clouds come in scan order, so consecutive points often share a voxel: the
  // last key is remembered to skip the table lookup.
  std::uint64_t last_key = kEmpty;
  int last_voxel = -1;
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    const std::uint64_t key = PackKey(p, inv_leaf);
    int voxel = last_voxel;
    if (key != last_key) {
      size_t slot = Mix(key) & mask;
      while (table[slot].key != kEmpty && table[slot].key != key) slot = (slot + 1) & mask;
      voxel = table[slot].voxel;
      if (voxel < 0) {
        voxel = static_cast<int>(centroids->size());
        table[slot] = Slot{key, voxel};
        centroids->push_back(Eigen::Vector3f::Zero());
        counts.push_back(0);
      }
      last_key = key;
      last_voxel = voxel;
    }
    (*centroids)[voxel] += p;
    ++counts[voxel];
    if (voxel_of_point != nullptr) (*voxel_of_point)[i] = voxel;
  }
  for (size_t v = 0; v < centroids->size(); ++v) {
    (*centroids)[v] /= static_cast<float>(counts[v]);
  }
}

}  // namespace hpose
