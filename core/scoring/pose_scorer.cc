#include "core/scoring/pose_scorer.h"

#include <algorithm>
#include <cstdint>
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

}  // namespace

ClusterVoxels VoxeliseCluster(const std::vector<Eigen::Vector3f>& points_ground,
                              double resolution_m) {
  ClusterVoxels out;
  out.resolution_m = resolution_m;
  std::vector<std::uint64_t> keys;
  if (PackedCells(points_ground, resolution_m, &keys)) {
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
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
  out.cells.erase(std::unique(out.cells.begin(), out.cells.end()), out.cells.end());
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
