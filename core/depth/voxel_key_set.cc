#include "core/depth/voxel_key_set.h"

#include "core/depth/voxel_downsample.h"

namespace hpose {
namespace {

// Keys use 63 bits (21 an axis), so all 64 set is no key.
constexpr std::uint64_t kEmpty = ~std::uint64_t{0};

}  // namespace

size_t VoxelKeySet::Slot(std::uint64_t key) const {
  // Fibonacci hashing: the product's top bits, as many as the table needs.
  return static_cast<size_t>((key * 0x9E3779B97F4A7C15ull) >> shift_);
}

void VoxelKeySet::Build(const std::vector<Eigen::Vector3f>& points, float leaf_m) {
  inv_leaf_ = 1.0f / leaf_m;
  size_t capacity = 16;
  int bits = 4;
  while (capacity < 4 * points.size()) {
    capacity *= 2;
    ++bits;
  }
  slots_.assign(capacity, kEmpty);
  mask_ = capacity - 1;
  shift_ = 64 - bits;
  size_ = 0;
  std::vector<std::uint64_t> keys(points.size());
  if (!points.empty()) PackVoxelKeys(points.data(), points.size(), inv_leaf_, keys.data());
  for (const std::uint64_t key : keys) {
    size_t s = Slot(key);
    while (slots_[s] != kEmpty && slots_[s] != key) s = (s + 1) & mask_;
    if (slots_[s] == kEmpty) {
      slots_[s] = key;
      ++size_;
    }
  }
}

bool VoxelKeySet::Contains(const Eigen::Vector3f& p) const {
  if (size_ == 0) return false;
  std::uint64_t key;
  PackVoxelKeysScalar(&p, 1, inv_leaf_, &key);
  for (size_t s = Slot(key);; s = (s + 1) & mask_) {
    if (slots_[s] == key) return true;
    if (slots_[s] == kEmpty) return false;
  }
}

}  // namespace hpose
