#include "core/depth/neighbour_sampler.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numeric>

namespace hpose {
namespace {

// 21 bits per axis, as the voxel keys: +-2^20 cells, clamped beyond.
constexpr std::int64_t kAxisLimit = (1 << 20) - 1;

std::int32_t CellCoord(float v, float inv_side) {
  const double scaled = std::floor(static_cast<double>(v) * inv_side);
  return static_cast<std::int32_t>(
      std::clamp(scaled, -static_cast<double>(kAxisLimit), static_cast<double>(kAxisLimit)));
}

std::uint64_t PackCell(std::int64_t x, std::int64_t y, std::int64_t z) {
  return (static_cast<std::uint64_t>(x + kAxisLimit) << 42) |
         (static_cast<std::uint64_t>(y + kAxisLimit) << 21) |
         static_cast<std::uint64_t>(z + kAxisLimit);
}

}  // namespace

NeighbourSampler::NeighbourSampler(const std::vector<Eigen::Vector3f>& points, float radius_m)
    : points_(points), radius2_(radius_m * radius_m) {
  assert(radius_m > 0.0f);
  const int n = static_cast<int>(points.size());
  const float inv_side = 1.0f / radius_m;
  std::vector<std::array<std::int32_t, 3>> point_coords(n);
  std::vector<std::uint64_t> keys(n);
  for (int i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) point_coords[i][a] = CellCoord(points[i][a], inv_side);
    keys[i] = PackCell(point_coords[i][0], point_coords[i][1], point_coords[i][2]);
  }
  sorted_.resize(n);
  std::iota(sorted_.begin(), sorted_.end(), 0);
  std::sort(sorted_.begin(), sorted_.end(),
            [&](int a, int b) { return keys[a] < keys[b] || (keys[a] == keys[b] && a < b); });
  cell_of_point_.resize(n);
  for (int k = 0; k < n; ++k) {
    const int i = sorted_[k];
    if (cell_keys_.empty() || cell_keys_.back() != keys[i]) {
      cell_keys_.push_back(keys[i]);
      cell_start_.push_back(k);
      coords_.push_back(point_coords[i]);
    }
    cell_of_point_[i] = static_cast<std::int32_t>(cell_keys_.size() - 1);
  }
  cell_start_.push_back(n);
  blocks_.resize(cell_keys_.size());
}

bool NeighbourSampler::Near(int centre, int i) const {
  return (points_[i] - points_[centre]).squaredNorm() <= radius2_;
}

const NeighbourSampler::Block& NeighbourSampler::BlockOf(int centre) {
  const int cell = cell_of_point_[centre];
  Block& block = blocks_[cell];
  if (block.count > 0) return block;  // made: it holds at least the cell's own points.
  const std::array<std::int32_t, 3>& c = coords_[cell];
  for (int dx = -1; dx <= 1; ++dx) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dz = -1; dz <= 1; ++dz) {
        const std::int64_t x = std::int64_t{c[0]} + dx, y = std::int64_t{c[1]} + dy,
                           z = std::int64_t{c[2]} + dz;
        if (std::abs(x) > kAxisLimit || std::abs(y) > kAxisLimit || std::abs(z) > kAxisLimit) {
          continue;
        }
        const std::uint64_t key = PackCell(x, y, z);
        const auto it = std::lower_bound(cell_keys_.begin(), cell_keys_.end(), key);
        if (it == cell_keys_.end() || *it != key) continue;
        const int k = static_cast<int>(it - cell_keys_.begin());
        block.ranges.emplace_back(cell_start_[k], cell_start_[k + 1]);
        block.count += cell_start_[k + 1] - cell_start_[k];
      }
    }
  }
  return block;
}

int NeighbourSampler::DrawOne(int centre, int exclude, std::mt19937* rng) {
  const Block& block = BlockOf(centre);
  for (int t = 0; t < kMaxTries; ++t) {
    int r = static_cast<int>((*rng)() % static_cast<std::uint32_t>(block.count));
    int i = -1;
    for (const auto& [begin, end] : block.ranges) {
      if (r < end - begin) {
        i = sorted_[begin + r];
        break;
      }
      r -= end - begin;
    }
    if (i != centre && i != exclude && Near(centre, i)) return i;
  }
  // Many misses: few of the block's points are neighbours. Pick among the listed ones.
  scratch_.clear();
  for (const auto& [begin, end] : block.ranges) {
    for (int k = begin; k < end; ++k) {
      const int i = sorted_[k];
      if (i != centre && i != exclude && Near(centre, i)) scratch_.push_back(i);
    }
  }
  if (scratch_.empty()) return -1;
  return scratch_[(*rng)() % static_cast<std::uint32_t>(scratch_.size())];
}

bool NeighbourSampler::DrawPair(int centre, std::mt19937* rng, int* first, int* second) {
  assert(centre >= 0 && centre < static_cast<int>(points_.size()));
  const int a = DrawOne(centre, -1, rng);
  if (a < 0) return false;
  const int b = DrawOne(centre, a, rng);
  if (b < 0) return false;
  *first = a;
  *second = b;
  return true;
}

void NeighbourSampler::Neighbours(int centre, std::vector<int>* out) const {
  out->clear();
  for (int i = 0; i < static_cast<int>(points_.size()); ++i) {
    if (i != centre && Near(centre, i)) out->push_back(i);
  }
}

}  // namespace hpose
