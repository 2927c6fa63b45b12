#include "core/scoring/pose_scorer.h"

#include <algorithm>
#include <cstdint>
#include <functional>
#include <tuple>

#include "core/scoring/fast_scorer.h"
#include "core/scoring/octomap_scorer.h"

namespace hpose {

namespace {

// Cells packed into one word, 21 bits an axis offset by 2^20, so that the words sort as the
// cells do in (x, y, z) order (a sort of plain integers instead of a tuple compare).
constexpr int kCellBits = 21;
constexpr int kCellOffset = 1 << (kCellBits - 1);
constexpr std::uint64_t kCellMask = (std::uint64_t{1} << kCellBits) - 1;

// floor(v) for |v| <= 2^20 without a libm call: CellOf's cell, axis by axis.
int FloorSmall(double v) {
  const int t = static_cast<int>(v);
  return t - (static_cast<double>(t) > v ? 1 : 0);
}

Eigen::Vector3i UnpackCell(std::uint64_t key) {
  Eigen::Vector3i c;
  for (int axis = 2; axis >= 0; --axis) {
    c[axis] = static_cast<int>(key & kCellMask) - kCellOffset;
    key >>= kCellBits;
  }
  return c;
}

// The packed cells of the finite points, or false when a cell lies beyond +-2^20 (kilometres
// away), which the packing cannot hold.
bool PackedCells(const std::vector<Eigen::Vector3f>& points, double resolution_m,
                 std::vector<std::uint64_t>* keys) {
  const double f = 1.0 / resolution_m;  // as CellOf.
  keys->reserve(points.size());
  for (const Eigen::Vector3f& p : points) {
    if (!p.allFinite()) continue;
    std::uint64_t key = 0;
    for (int axis = 0; axis < 3; ++axis) {
      const double v = f * static_cast<double>(p[axis]);
      if (!(v >= -kCellOffset && v < kCellOffset)) return false;
      key = (key << kCellBits) | static_cast<std::uint64_t>(FloorSmall(v) + kCellOffset);
    }
    keys->push_back(key);
  }
  return true;
}

// The distinct cells of `keys` in (x, y, z) order, as sorting the keys gives them, from one bit
// per cell of their box (a cluster's box holds some tens of cells per key, and a pass over its
// bits costs less than a sort); with two_points_a_cell only the cells two or more keys share,
// from a second bit per cell. False, with nothing written, when the box holds too many cells
// for that.
bool DistinctCellsByBits(const std::vector<std::uint64_t>& keys, bool two_points_a_cell,
                         std::vector<Eigen::Vector3i>* cells) {
  if (keys.empty()) return false;
  std::uint64_t lo[3], hi[3];
  for (int axis = 0; axis < 3; ++axis) {
    lo[axis] = kCellMask;
    hi[axis] = 0;
  }
  for (const std::uint64_t key : keys) {
    for (int axis = 0; axis < 3; ++axis) {
      const std::uint64_t v = (key >> (kCellBits * (2 - axis))) & kCellMask;
      lo[axis] = std::min(lo[axis], v);
      hi[axis] = std::max(hi[axis], v);
    }
  }
  const std::uint64_t ny = hi[1] - lo[1] + 1, nz = hi[2] - lo[2] + 1;
  const std::uint64_t volume = (hi[0] - lo[0] + 1) * ny * nz;
  // A word of bits costs about what a key costs in the sort.
  if (volume > 64 * (keys.size() + 1024) || volume > (std::uint64_t{1} << 27)) return false;
  std::vector<std::uint64_t> bits((volume + 63) / 64, 0);
  // With two_points_a_cell, `bits` holds the cells seen once and `again` those seen twice.
  std::vector<std::uint64_t> again(two_points_a_cell ? bits.size() : 0, 0);
  const auto index_of = [&](std::uint64_t key) {
    const std::uint64_t x = (key >> (2 * kCellBits)) - lo[0];
    const std::uint64_t y = ((key >> kCellBits) & kCellMask) - lo[1];
    const std::uint64_t z = (key & kCellMask) - lo[2];
    return (x * ny + y) * nz + z;
  };
  if (two_points_a_cell) {
    for (const std::uint64_t key : keys) {
      const std::uint64_t i = index_of(key);
      const std::uint64_t bit = std::uint64_t{1} << (i % 64);
      again[i / 64] |= bits[i / 64] & bit;
      bits[i / 64] |= bit;
    }
    bits.swap(again);
  } else {
    for (const std::uint64_t key : keys) {
      const std::uint64_t i = index_of(key);
      bits[i / 64] |= std::uint64_t{1} << (i % 64);
    }
  }
  std::size_t count = 0;
  for (const std::uint64_t w : bits) count += static_cast<std::size_t>(__builtin_popcountll(w));
  cells->clear();
  cells->reserve(count);
  for (std::size_t k = 0; k < bits.size(); ++k) {
    for (std::uint64_t w = bits[k]; w != 0; w &= w - 1) {
      const std::uint64_t i = 64 * k + static_cast<std::uint64_t>(__builtin_ctzll(w));
      const std::uint64_t z = i % nz, xy = i / nz;
      cells->emplace_back(static_cast<int>(xy / ny + lo[0]) - kCellOffset,
                          static_cast<int>(xy % ny + lo[1]) - kCellOffset,
                          static_cast<int>(z + lo[2]) - kCellOffset);
    }
  }
  return true;
}

// Keeps, of sorted `v`, one of each run of equal elements: every run, or with
// two_points_a_cell those of two or more.
template <typename T, typename Equal>
void KeepDistinct(std::vector<T>* v, bool two_points_a_cell, Equal equal) {
  size_t n = 0;
  for (size_t i = 0; i < v->size();) {
    size_t j = i + 1;
    while (j < v->size() && equal((*v)[j], (*v)[i])) ++j;
    if (!two_points_a_cell || j - i >= 2) (*v)[n++] = (*v)[i];
    i = j;
  }
  v->resize(n);
}

}  // namespace

ClusterVoxels VoxeliseCluster(const std::vector<Eigen::Vector3f>& points_ground,
                              double resolution_m, bool two_points_a_cell) {
  ClusterVoxels out;
  out.resolution_m = resolution_m;
  std::vector<std::uint64_t> keys;
  if (PackedCells(points_ground, resolution_m, &keys)) {
    if (DistinctCellsByBits(keys, two_points_a_cell, &out.cells)) return out;
    std::sort(keys.begin(), keys.end());
    KeepDistinct(&keys, two_points_a_cell, std::equal_to<>());
    out.cells.resize(keys.size());
    for (size_t i = 0; i < keys.size(); ++i) out.cells[i] = UnpackCell(keys[i]);
    return out;
  }
  // Far cells: CellOf's cells compared axis by axis.
  out.cells.reserve(points_ground.size());
  for (const Eigen::Vector3f& p : points_ground) {
    if (p.allFinite()) out.cells.push_back(CellOf(p, resolution_m));
  }
  auto less = [](const Eigen::Vector3i& a, const Eigen::Vector3i& b) {
    return std::tie(a.x(), a.y(), a.z()) < std::tie(b.x(), b.y(), b.z());
  };
  std::sort(out.cells.begin(), out.cells.end(), less);
  KeepDistinct(&out.cells, two_points_a_cell,
               [](const Eigen::Vector3i& a, const Eigen::Vector3i& b) { return a == b; });
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
