#include "core/scoring/fast_scorer.h"

#include <algorithm>

namespace hpose {

FastScorer::FastScorer(const ClusterVoxels& cluster, const PoseLattice& lattice)
    : lattice_(lattice), cluster_voxels_(static_cast<int>(cluster.cells.size())) {
  for (int s = 0; s < 31; ++s) {
    if ((1 << s) == lattice.subdivisions) shift_ = s;
  }
  if (cluster.cells.empty()) return;
  Eigen::Vector3i lo = cluster.cells.front();
  Eigen::Vector3i hi = lo;
  for (const Eigen::Vector3i& c : cluster.cells) {
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  }
  min_ = lo;
  size_ = hi - lo + Eigen::Vector3i::Ones();
  const size_t n = static_cast<size_t>(size_.x()) * size_.y() * size_.z();
  occupied_.assign(n, 0);
  stamp_.assign(n, 0);
  for (const Eigen::Vector3i& c : cluster.cells) {
    const Eigen::Vector3i d = c - min_;
    occupied_[(static_cast<size_t>(d.z()) * size_.y() + d.y()) * size_.x() + d.x()] = 1;
  }
}

bool FastScorer::Occupied(const Eigen::Vector3i& cell) const {
  const Eigen::Vector3i d = cell - min_;
  if ((d.array() < 0).any() || (d.array() >= size_.array()).any()) return false;
  return occupied_[(static_cast<size_t>(d.z()) * size_.y() + d.y()) * size_.x() + d.x()] != 0;
}

int FastScorer::Hits(const RotatedTemplate& rotated, int ix, int iy) const {
  if (occupied_.empty()) return 0;
  if (++current_stamp_ == 0) {  // wrapped: clear so old stamps cannot alias.
    std::fill(stamp_.begin(), stamp_.end(), 0);
    current_stamp_ = 1;
  }
  const std::uint32_t stamp = current_stamp_;
  const int sx = size_.x();
  const int sy = size_.y();
  const int sz = size_.z();
  // Offsets folded in: cell - min = floor_div(q + i, S) - min.
  const int mx = min_.x();
  const int my = min_.y();
  const int mz = min_.z();
  int hits = 0;
  auto visit = [&](int x, int y, int z) {
    const unsigned dx = static_cast<unsigned>(x - mx);
    const unsigned dy = static_cast<unsigned>(y - my);
    const unsigned dz = static_cast<unsigned>(z - mz);
    if (dx >= static_cast<unsigned>(sx) || dy >= static_cast<unsigned>(sy) ||
        dz >= static_cast<unsigned>(sz)) {
      return;
    }
    const size_t idx = (static_cast<size_t>(dz) * sy + dy) * sx + dx;
    if (occupied_[idx] && stamp_[idx] != stamp) {
      stamp_[idx] = stamp;
      ++hits;
    }
  };
  if (shift_ >= 0) {
    const int sh = shift_;
    ForEachPlacedVoxel(rotated, [&](const Eigen::Vector3i& q) {
      // Arithmetic right shift is floor division by a power of two (C++20; GCC always).
      visit((q.x() + ix) >> sh, (q.y() + iy) >> sh, q.z());
    });
  } else {
    const int s = lattice_.subdivisions;
    ForEachPlacedVoxel(rotated, [&](const Eigen::Vector3i& q) {
      visit(FloorDiv(q.x() + ix, s), FloorDiv(q.y() + iy, s), q.z());
    });
  }
  return hits;
}

}  // namespace hpose
