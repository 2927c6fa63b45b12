#include "core/scoring/column_occupancy.h"

#include <algorithm>
#include <cassert>

namespace hpose {
namespace {

inline int Popcount(std::uint64_t v) { return __builtin_popcountll(v); }

}  // namespace

ColumnOccupancy::ColumnOccupancy(const ClusterVoxels& cluster, const PoseLattice& lattice,
                                 int z_base, int z_words, int max_level, Filter filter)
    : lattice_(lattice), words_(z_words) {
  assert(z_words >= 1 && max_level >= 0);
  for (int s = 0; s < 31; ++s) {
    if ((1 << s) == lattice.subdivisions) shift_ = s;
  }
  if (!cluster.cells.empty()) {
    int x_lo = cluster.cells.front().x(), x_hi = x_lo;
    int y_lo = cluster.cells.front().y(), y_hi = y_lo;
    for (const Eigen::Vector3i& c : cluster.cells) {
      x_lo = std::min(x_lo, c.x());
      x_hi = std::max(x_hi, c.x());
      y_lo = std::min(y_lo, c.y());
      y_hi = std::max(y_hi, c.y());
    }
    base_.x0 = x_lo;
    base_.y0 = y_lo;
    base_.nx = x_hi - x_lo + 1;
    base_.ny = y_hi - y_lo + 1;
  }
  base_.masks.assign(static_cast<size_t>(base_.nx) * base_.ny * words_, 0);
  for (const Eigen::Vector3i& c : cluster.cells) {
    const int bit = c.z() - z_base;
    if (bit < 0 || bit >= 64 * words_) continue;
    const size_t cell = static_cast<size_t>(c.y() - base_.y0) * base_.nx + (c.x() - base_.x0);
    base_.masks[cell * words_ + bit / 64] |= std::uint64_t{1} << (bit % 64);
  }
  stamp_.assign(static_cast<size_t>(base_.nx) * base_.ny, 0);
  acc_.assign(base_.masks.size(), 0);

  const int s = lattice.subdivisions;
  const bool max_filter = filter == Filter::kMax;
  for (int k = 0; k <= max_level; ++k) {
    Level level;
    // A block of 2^k steps starting at sub-voxel offset r in [0, S) sweeps
    // floor((r + 2^k - 1) / S) + 1 cells: min_len at r = 0, at most one more.
    level.min_len = ((1 << k) - 1) / s + 1;
    for (int ex = 0; ex < 2; ++ex) {
      for (int ey = 0; ey < 2; ++ey) {
        level.grids[ex][ey] = (k == 0 && (ex || ey)) ? Grid()
                                                     : Filtered(base_, level.min_len + ex,
                                                                level.min_len + ey, max_filter);
      }
    }
    levels_.push_back(std::move(level));
  }
}

ColumnOccupancy::Grid ColumnOccupancy::Filtered(const Grid& g0, int len_x, int len_y,
                                                bool max_filter) const {
  if (len_x == 1 && len_y == 1) return g0;
  // kMax: every window that touches the base; kMin: only windows inside it (others AND to 0).
  Grid g;
  g.x0 = max_filter ? g0.x0 - (len_x - 1) : g0.x0;
  g.y0 = max_filter ? g0.y0 - (len_y - 1) : g0.y0;
  g.nx = std::max(0, max_filter ? g0.nx + len_x - 1 : g0.nx - len_x + 1);
  g.ny = std::max(0, max_filter ? g0.ny + len_y - 1 : g0.ny - len_y + 1);
  const std::uint64_t identity = max_filter ? 0 : ~std::uint64_t{0};
  auto combine = [max_filter](std::uint64_t a, std::uint64_t b) {
    return max_filter ? (a | b) : (a & b);
  };
  // Separable: first along x into `tmp` (g.nx by g0.ny), then along y.
  std::vector<std::uint64_t> tmp(static_cast<size_t>(g.nx) * g0.ny * words_, 0);
  for (int y = 0; y < g0.ny; ++y) {
    for (int x = 0; x < g.nx; ++x) {
      const int from = std::max(0, x + g.x0 - g0.x0);
      const int to = std::min(g0.nx, x + g.x0 - g0.x0 + len_x);
      for (int w = 0; w < words_; ++w) {
        std::uint64_t m = identity;
        for (int xb = from; xb < to; ++xb) {
          m = combine(m, g0.masks[(static_cast<size_t>(y) * g0.nx + xb) * words_ + w]);
        }
        tmp[(static_cast<size_t>(y) * g.nx + x) * words_ + w] = m;
      }
    }
  }
  g.masks.assign(static_cast<size_t>(g.nx) * g.ny * words_, 0);
  for (int y = 0; y < g.ny; ++y) {
    const int from = std::max(0, y + g.y0 - g0.y0);
    const int to = std::min(g0.ny, y + g.y0 - g0.y0 + len_y);
    for (int x = 0; x < g.nx; ++x) {
      for (int w = 0; w < words_; ++w) {
        std::uint64_t m = identity;
        for (int yb = from; yb < to; ++yb) {
          m = combine(m, tmp[(static_cast<size_t>(yb) * g.nx + x) * words_ + w]);
        }
        g.masks[(static_cast<size_t>(y) * g.nx + x) * words_ + w] = m;
      }
    }
  }
  return g;
}

inline int ColumnOccupancy::FloorDivS(int v) const {
  return shift_ >= 0 ? (v >> shift_) : FloorDiv(v, lattice_.subdivisions);
}

int ColumnOccupancy::Hits(const RotatedTemplate& rotated, int ix, int iy) const {
  assert(rotated.z_words == words_);
  const Grid& g = base_;
  if (g.masks.empty()) return 0;
  if (++current_stamp_ == 0) {
    std::fill(stamp_.begin(), stamp_.end(), 0);
    current_stamp_ = 1;
  }
  touched_.clear();
  const size_t n = rotated.column_q.size();
  for (size_t c = 0; c < n; ++c) {
    const unsigned dx = static_cast<unsigned>(FloorDivS(rotated.column_q[c].x() + ix) - g.x0);
    const unsigned dy = static_cast<unsigned>(FloorDivS(rotated.column_q[c].y() + iy) - g.y0);
    if (dx >= static_cast<unsigned>(g.nx) || dy >= static_cast<unsigned>(g.ny)) continue;
    const int idx = static_cast<int>(dy * g.nx + dx);
    const std::uint64_t* col = &rotated.column_masks[c * words_];
    std::uint64_t* acc = &acc_[static_cast<size_t>(idx) * words_];
    if (stamp_[idx] != current_stamp_) {
      stamp_[idx] = current_stamp_;
      touched_.push_back(idx);
      for (int w = 0; w < words_; ++w) acc[w] = col[w];
    } else {
      for (int w = 0; w < words_; ++w) acc[w] |= col[w];
    }
  }
  int hits = 0;
  for (int idx : touched_) {
    const std::uint64_t* acc = &acc_[static_cast<size_t>(idx) * words_];
    const std::uint64_t* occ = &g.masks[static_cast<size_t>(idx) * words_];
    for (int w = 0; w < words_; ++w) hits += Popcount(acc[w] & occ[w]);
  }
  return hits;
}

int ColumnOccupancy::Bound(const RotatedTemplate& rotated, int a, int b, int level) const {
  assert(level >= 0 && level < static_cast<int>(levels_.size()));
  const Level& lv = levels_[level];
  const int span = (1 << level) - 1;
  int bound = 0;
  const size_t n = rotated.column_q.size();
  for (size_t c = 0; c < n; ++c) {
    const int qa = rotated.column_q[c].x() + a;
    const int qb = rotated.column_q[c].y() + b;
    const int x0 = FloorDivS(qa), y0 = FloorDivS(qb);
    const int ex = FloorDivS(qa + span) - x0 + 1 - lv.min_len;  // 0 or 1.
    const int ey = FloorDivS(qb + span) - y0 + 1 - lv.min_len;
    const Grid& g = lv.grids[ex][ey];
    const unsigned dx = static_cast<unsigned>(x0 - g.x0);
    const unsigned dy = static_cast<unsigned>(y0 - g.y0);
    if (dx >= static_cast<unsigned>(g.nx) || dy >= static_cast<unsigned>(g.ny)) continue;
    const size_t idx = static_cast<size_t>(dy) * g.nx + dx;
    if (words_ == 1) {
      bound += Popcount(rotated.column_masks[c] & g.masks[idx]);
    } else {
      for (int w = 0; w < words_; ++w) {
        bound += Popcount(rotated.column_masks[c * words_ + w] & g.masks[idx * words_ + w]);
      }
    }
  }
  return bound;
}

}  // namespace hpose
