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
  Grid base;
  bool any = false;
  int x_lo = 0, x_hi = -1, y_lo = 0, y_hi = -1;
  for (const Eigen::Vector3i& c : cluster.cells) {
    if (!any) {
      x_lo = x_hi = c.x();
      y_lo = y_hi = c.y();
      any = true;
    }
    x_lo = std::min(x_lo, c.x());
    x_hi = std::max(x_hi, c.x());
    y_lo = std::min(y_lo, c.y());
    y_hi = std::max(y_hi, c.y());
  }
  if (any) {
    base.x0 = x_lo;
    base.y0 = y_lo;
    base.nx = x_hi - x_lo + 1;
    base.ny = y_hi - y_lo + 1;
  }
  base.masks.assign(static_cast<size_t>(base.nx) * base.ny * words_, 0);
  for (const Eigen::Vector3i& c : cluster.cells) {
    const int bit = c.z() - z_base;
    if (bit < 0 || bit >= 64 * words_) continue;
    const size_t cell = static_cast<size_t>(c.y() - base.y0) * base.nx + (c.x() - base.x0);
    base.masks[cell * words_ + bit / 64] |= std::uint64_t{1} << (bit % 64);
  }
  stamp_.assign(static_cast<size_t>(base.nx) * base.ny, 0);
  acc_.assign(base.masks.size(), 0);
  levels_.push_back(std::move(base));

  const int s = lattice.subdivisions;
  const bool max_filter = filter == Filter::kMax;
  for (int k = 1; k <= max_level; ++k) {
    const Grid& g0 = levels_.front();
    const int len = ((1 << k) + s - 2) / s + 1;  // cells a block of 2^k steps can span.
    // kMax: every window that touches the base; kMin: only windows inside it (others AND to 0).
    Grid g;
    g.x0 = max_filter ? g0.x0 - (len - 1) : g0.x0;
    g.y0 = max_filter ? g0.y0 - (len - 1) : g0.y0;
    g.nx = std::max(0, max_filter ? g0.nx + len - 1 : g0.nx - len + 1);
    g.ny = std::max(0, max_filter ? g0.ny + len - 1 : g0.ny - len + 1);
    const std::uint64_t identity = max_filter ? 0 : ~std::uint64_t{0};
    auto combine = [max_filter](std::uint64_t a, std::uint64_t b) {
      return max_filter ? (a | b) : (a & b);
    };
    // Separable: first along x into `tmp` (g.nx by g0.ny), then along y.
    std::vector<std::uint64_t> tmp(static_cast<size_t>(g.nx) * g0.ny * words_, 0);
    for (int y = 0; y < g0.ny; ++y) {
      for (int x = 0; x < g.nx; ++x) {
        const int from = std::max(0, x + g.x0 - g0.x0);
        const int to = std::min(g0.nx, x + g.x0 - g0.x0 + len);
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
      const int to = std::min(g0.ny, y + g.y0 - g0.y0 + len);
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
    levels_.push_back(std::move(g));
  }
}

inline int ColumnOccupancy::Index(const Grid& g, int qx, int qy, int a, int b) const {
  int x, y;
  if (shift_ >= 0) {
    x = (qx + a) >> shift_;
    y = (qy + b) >> shift_;
  } else {
    x = FloorDiv(qx + a, lattice_.subdivisions);
    y = FloorDiv(qy + b, lattice_.subdivisions);
  }
  const unsigned dx = static_cast<unsigned>(x - g.x0);
  const unsigned dy = static_cast<unsigned>(y - g.y0);
  if (dx >= static_cast<unsigned>(g.nx) || dy >= static_cast<unsigned>(g.ny)) return -1;
  return static_cast<int>(dy * g.nx + dx);
}

int ColumnOccupancy::Hits(const RotatedTemplate& rotated, int ix, int iy) const {
  assert(rotated.z_words == words_);
  const Grid& g = levels_.front();
  if (g.masks.empty()) return 0;
  if (++current_stamp_ == 0) {
    std::fill(stamp_.begin(), stamp_.end(), 0);
    current_stamp_ = 1;
  }
  touched_.clear();
  const size_t n = rotated.column_q.size();
  for (size_t c = 0; c < n; ++c) {
    const int idx = Index(g, rotated.column_q[c].x(), rotated.column_q[c].y(), ix, iy);
    if (idx < 0) continue;
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
  const Grid& g = levels_[level];
  if (g.masks.empty()) return 0;
  int bound = 0;
  const size_t n = rotated.column_q.size();
  if (words_ == 1) {
    for (size_t c = 0; c < n; ++c) {
      const int idx = Index(g, rotated.column_q[c].x(), rotated.column_q[c].y(), a, b);
      if (idx >= 0) bound += Popcount(rotated.column_masks[c] & g.masks[idx]);
    }
    return bound;
  }
  for (size_t c = 0; c < n; ++c) {
    const int idx = Index(g, rotated.column_q[c].x(), rotated.column_q[c].y(), a, b);
    if (idx < 0) continue;
    for (int w = 0; w < words_; ++w) {
      bound += Popcount(rotated.column_masks[c * words_ + w] &
                        g.masks[static_cast<size_t>(idx) * words_ + w]);
    }
  }
  return bound;
}

}  // namespace hpose
