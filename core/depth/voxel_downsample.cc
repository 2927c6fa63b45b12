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

// floor(x) for |x| <= kAxisLimit without a libm call (x86-64's baseline has no SSE4.1 round).
std::int64_t FloorToInt(float x) {
  const std::int64_t truncated = static_cast<std::int64_t>(x);
  return truncated - (static_cast<float>(truncated) > x ? 1 : 0);
}

std::uint64_t PackKey(const Eigen::Vector3f& p, float inv_leaf) {
  // Clamping before flooring gives floor-then-clamp's result: the limit is an integer.
  const float limit = static_cast<float>(kAxisLimit);
  std::uint64_t key = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const std::int64_t cell = FloorToInt(std::clamp(p[axis] * inv_leaf, -limit, limit));
    key = (key << 21) | static_cast<std::uint64_t>(cell + kAxisLimit);
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

  // Open addressing, at most half full: the keys in one array (what a probe reads) and each
  // key's voxel in another (read once the key matches). Sized for a quarter of the points as
  // voxels (depth clouds have several points per voxel) and doubled when that is exceeded: a
  // table sized for every point would not fit in the cache for a 640x480 frame and would cost
  // more than it saves.
  size_t capacity = 64;
  while (capacity < points.size() / 2) capacity <<= 1;
  size_t mask = capacity - 1;
  std::vector<std::uint64_t> table(capacity, kEmpty);
  std::vector<int> table_voxel(capacity);
  std::vector<std::uint64_t> keys;  // of each voxel, to rehash.
  std::vector<int> counts;
  counts.reserve(points.size() / 4 + 16);
  keys.reserve(points.size() / 4 + 16);
  centroids->reserve(points.size() / 4 + 16);
  auto find_slot = [&](std::uint64_t key) {
    size_t slot = Mix(key) & mask;
    while (table[slot] != kEmpty && table[slot] != key) slot = (slot + 1) & mask;
    return slot;
  };

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
      const size_t slot = find_slot(key);
      if (table[slot] == key) {
        voxel = table_voxel[slot];
      } else {
        voxel = static_cast<int>(centroids->size());
        table[slot] = key;
        table_voxel[slot] = voxel;
        centroids->push_back(Eigen::Vector3f::Zero());
        counts.push_back(0);
        keys.push_back(key);
        if (2 * keys.size() > capacity) {
          capacity <<= 1;
          mask = capacity - 1;
          table.assign(capacity, kEmpty);
          table_voxel.resize(capacity);
          for (size_t v = 0; v < keys.size(); ++v) {
            const size_t to = find_slot(keys[v]);
            table[to] = keys[v];
            table_voxel[to] = static_cast<int>(v);
          }
        }
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
