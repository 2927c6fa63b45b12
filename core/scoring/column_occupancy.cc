#include "core/scoring/column_occupancy.h"

#include <algorithm>
#include <cassert>
#include <numeric>

#include "core/scoring/gather_sums.h"
#include "core/scoring/popcount_clones.h"

namespace hpose {
namespace {

inline int Popcount(std::uint64_t v) { return __builtin_popcountll(v); }

// out[s * out_stride] = combination over t in [0, len) of in[(start + s + t) * in_stride] for
// s in [0, n_out), where entries outside [0, n_in) are 0. Sparse-table doubling: O(log len)
// passes over a line instead of len. `scratch` is reused between calls.
void Window1D(const std::uint64_t* in, int n_in, std::ptrdiff_t in_stride, int start, int len,
              bool max_filter, std::uint64_t* out, int n_out, std::ptrdiff_t out_stride,
              std::vector<std::uint64_t>* scratch) {
  const int m = n_out + len - 1;
  scratch->resize(static_cast<size_t>(m));
  std::uint64_t* cur = scratch->data();
  for (int i = 0; i < m; ++i) {
    const int j = start + i;
    cur[i] = (j >= 0 && j < n_in) ? in[j * in_stride] : 0;
  }
  int p = 1;
  for (; 2 * p <= len; p *= 2) {
    for (int i = 0; i + p < m; ++i)
      cur[i] = max_filter ? (cur[i] | cur[i + p]) : (cur[i] & cur[i + p]);
  }
  for (int s = 0; s < n_out; ++s) {
    const std::uint64_t v = max_filter ? (cur[s] | cur[s + len - p]) : (cur[s] & cur[s + len - p]);
    out[s * out_stride] = v;
  }
}

// Windows of 2 len (+ 0 or 1 per axis) from those of len + 0/1 (4 interleaved words a cell,
// e = 2 ex + ey): window 2 len + e at x = window len + e at x, then window len at x + len + e
// (per axis). Windows starting past the box lie past the voxels: empty (max) or reaching
// outside (min), 0 either way. Only the cells [x_lo, x_hi] x [y_lo, y_hi] are written; the cells
// whose four reads all lie in the box skip the checks.
template <bool kMax>
void DoubleWindows(const std::uint64_t* in, int nx, int ny, int len, int x_lo, int x_hi, int y_lo,
                   int y_hi, std::uint64_t* out) {
  const auto combine = [](std::uint64_t a, std::uint64_t b, std::uint64_t c, std::uint64_t d) {
    return kMax ? (a | b | c | d) : (a & b & c & d);
  };
  const auto at = [&](int x, int y, int e) -> std::uint64_t {
    return x < nx && y < ny ? in[(static_cast<std::ptrdiff_t>(y) * nx + x) * 4 + e] : 0;
  };
  const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(nx) * 4;
  for (int y = y_lo; y <= y_hi; ++y) {
    // Every read in the box: x + len + 1 < nx and y + len + 1 < ny.
    const int inside_end =
        y + len + 1 < ny ? std::min(x_hi + 1, std::max(x_lo, nx - len - 1)) : x_lo;
    const std::uint64_t* r0 = in + y * row;
    std::uint64_t* o = out + y * row;
    if (inside_end > x_lo) {
      const std::uint64_t* r1 = in + (y + len) * row;  // ey = 0
      const std::uint64_t* r2 = r1 + row;              // ey = 1
      const std::ptrdiff_t dx = 4 * static_cast<std::ptrdiff_t>(len);
      for (int x = x_lo; x < inside_end; ++x) {
        const std::ptrdiff_t i = 4 * static_cast<std::ptrdiff_t>(x);
        o[i + 0] = combine(r0[i + 0], r0[i + dx + 0], r1[i + 0], r1[i + dx]);
        o[i + 1] = combine(r0[i + 1], r0[i + dx + 1], r2[i + 0], r2[i + dx]);
        o[i + 2] = combine(r0[i + 2], r0[i + dx + 4], r1[i + 2], r1[i + dx + 4]);
        o[i + 3] = combine(r0[i + 3], r0[i + dx + 5], r2[i + 2], r2[i + dx + 4]);
      }
    }
    for (int x = inside_end; x <= x_hi; ++x) {
      for (int ex = 0; ex < 2; ++ex) {
        for (int ey = 0; ey < 2; ++ey) {
          const int x1 = x + len + ex, y1 = y + len + ey;
          o[4 * x + 2 * ex + ey] =
              combine(at(x, y, 2 * ex + ey), at(x1, y, ey), at(x, y1, 2 * ex), at(x1, y1, 0));
        }
      }
    }
  }
}

// The bound sum for one 64-bit word per column and a power-of-two subdivision (the default
// lattice): per column two shifts per axis find the window's first cell and its length, one
// interleaved lookup gets the filtered mask.
HPOSE_POPCNT_CLONES
int SumOneWordPow2(const std::uint64_t* data, int x0, int y0, int nx, int ny, int shift, int extra,
                   const Eigen::Vector2i* q, const std::uint64_t* masks, int n, int a, int b,
                   int span) {
  int sum = 0;
  for (int c = 0; c < n; ++c) {
    const int qa = q[c].x() + a;
    const int qb = q[c].y() + b;
    const int cx = qa >> shift;
    const int cy = qb >> shift;
    const int ex = ((qa + span) >> shift) - cx - extra;  // 0 or 1.
    const int ey = ((qb + span) >> shift) - cy - extra;
    const unsigned dx = static_cast<unsigned>(cx - x0);
    const unsigned dy = static_cast<unsigned>(cy - y0);
    if (dx >= static_cast<unsigned>(nx) || dy >= static_cast<unsigned>(ny)) continue;
    const size_t idx = (static_cast<size_t>(dy) * nx + dx) * 4 + 2 * ex + ey;
    sum += Popcount(masks[c] & data[idx]);
  }
  return sum;
}

// SumOneWordPow2 for the blocks at (a, b), (a + d S, b), (a, b + d S), (a + d S, b + d S): the
// same residues, so the same window lengths, d cells apart.
HPOSE_POPCNT_CLONES
void SumOneWordPow2x4(const std::uint64_t* data, int x0, int y0, int nx, int ny, int shift,
                      int extra, const Eigen::Vector2i* q, const std::uint64_t* masks, int n, int a,
                      int b, int span, int d, int out[4]) {
  int s00 = 0, s10 = 0, s01 = 0, s11 = 0;
  const size_t step_x = static_cast<size_t>(4) * d;
  const size_t step_y = static_cast<size_t>(4) * d * nx;
  for (int c = 0; c < n; ++c) {
    const int qa = q[c].x() + a;
    const int qb = q[c].y() + b;
    const int cx = qa >> shift;
    const int cy = qb >> shift;
    const int ex = ((qa + span) >> shift) - cx - extra;
    const int ey = ((qb + span) >> shift) - cy - extra;
    const unsigned dx = static_cast<unsigned>(cx - x0);
    const unsigned dy = static_cast<unsigned>(cy - y0);
    const unsigned dx1 = static_cast<unsigned>(cx + d - x0);
    const unsigned dy1 = static_cast<unsigned>(cy + d - y0);
    const bool in_x0 = dx < static_cast<unsigned>(nx), in_x1 = dx1 < static_cast<unsigned>(nx);
    const bool in_y0 = dy < static_cast<unsigned>(ny), in_y1 = dy1 < static_cast<unsigned>(ny);
    if (!((in_x0 || in_x1) && (in_y0 || in_y1))) continue;
    const std::uint64_t m = masks[c];
    // Index of (cx, cy) even when outside: only in-range cells are read.
    const std::ptrdiff_t idx =
        (static_cast<std::ptrdiff_t>(cy - y0) * nx + (cx - x0)) * 4 + 2 * ex + ey;
    if (in_y0) {
      if (in_x0) s00 += Popcount(m & data[idx]);
      if (in_x1) s10 += Popcount(m & data[idx + step_x]);
    }
    if (in_y1) {
      if (in_x0) s01 += Popcount(m & data[idx + step_y]);
      if (in_x1) s11 += Popcount(m & data[idx + step_y + step_x]);
    }
  }
  out[0] = s00;
  out[1] = s01;
  out[2] = s10;
  out[3] = s11;
}

// Any subdivision and any number of words.
HPOSE_POPCNT_CLONES
int SumGeneric(const std::uint64_t* data, int x0, int y0, int nx, int ny, int s, int extra,
               int words, const Eigen::Vector2i* q, const std::uint64_t* masks, int n, int a, int b,
               int span) {
  int sum = 0;
  for (int c = 0; c < n; ++c) {
    const int qa = q[c].x() + a;
    const int qb = q[c].y() + b;
    const int cx = FloorDiv(qa, s);
    const int cy = FloorDiv(qb, s);
    const int ex = FloorDiv(qa + span, s) - cx - extra;
    const int ey = FloorDiv(qb + span, s) - cy - extra;
    const unsigned dx = static_cast<unsigned>(cx - x0);
    const unsigned dy = static_cast<unsigned>(cy - y0);
    if (dx >= static_cast<unsigned>(nx) || dy >= static_cast<unsigned>(ny)) continue;
    const std::uint64_t* cell =
        &data[((static_cast<size_t>(dy) * nx + dx) * 4 + 2 * ex + ey) * words];
    const std::uint64_t* m = &masks[static_cast<size_t>(c) * words];
    for (int w = 0; w < words; ++w) sum += Popcount(m[w] & cell[w]);
  }
  return sum;
}

// Theta blocks, aligned: column c reads the level levels[c] points at (null: all its voxels
// count).
HPOSE_POPCNT_CLONES
void SumArcsAligned(const std::uint64_t* const* levels, std::ptrdiff_t base, std::ptrdiff_t row,
                    std::ptrdiff_t dx, std::ptrdiff_t dy, int blocks, const std::int32_t* cxe,
                    const std::int32_t* cy, const std::uint64_t* masks, int n, int out[4]) {
  int s[4] = {0, 0, 0, 0};
  for (int c = 0; c < n; ++c) {
    const std::uint64_t m = masks[c];
    if (levels[c] == nullptr) {
      const int all = Popcount(m);
      for (int k = 0; k < 4; ++k) s[k] += all;
      continue;
    }
    const std::uint64_t* p = levels[c] + base + cy[c] * row + cxe[c];
    s[0] += Popcount(m & p[0]);
    if (blocks == 2) {
      s[1] += Popcount(m & p[dy]);
      s[2] += Popcount(m & p[dx]);
      s[3] += Popcount(m & p[dx + dy]);
    }
  }
  for (int k = 0; k < 4; ++k) out[k] = s[k];
}

// Theta blocks, any layout: per column its level's window, range-checked.
HPOSE_POPCNT_CLONES
int SumArcColumn(const std::uint64_t* m, const std::uint64_t* cell, int words) {
  int hits = 0;
  for (int w = 0; w < words; ++w) hits += Popcount(m[w] & cell[w]);
  return hits;
}

// The smallest level whose blocks sweep `span` more sub-voxel steps than their first:
// 2^level - 1 >= span.
inline int LevelSweeping(int span) { return span <= 0 ? 0 : 32 - __builtin_clz(span); }

HPOSE_POPCNT_CLONES
int HitsOneWord(const std::uint64_t* acc, const std::uint64_t* occ, const int* touched, int n) {
  int hits = 0;
  for (int i = 0; i < n; ++i) hits += Popcount(acc[touched[i]] & occ[touched[i]]);
  return hits;
}

}  // namespace

ColumnOccupancy::ColumnOccupancy(const ClusterVoxels& cluster, const PoseLattice& lattice,
                                 int z_base, int z_words, int max_level, Filter filter,
                                 const CellRange* aligned_lookups)
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

  // Each level's own box: every window that touches the base starts in it; windows starting
  // elsewhere hold nothing (kMax) or reach outside the voxels (kMin: 0) and are never looked up
  // (or read as 0 in the aligned layout).
  CellRange common;
  aligned_ = aligned_lookups != nullptr && shift_ >= 0 && words_ == 1 &&
             aligned_lookups->x_hi >= aligned_lookups->x_lo &&
             aligned_lookups->y_hi >= aligned_lookups->y_lo;
  if (aligned_) {
    const int longest = ((1 << max_level) - 1) / lattice_.subdivisions + 1;
    common.x_lo = std::min(aligned_lookups->x_lo, base_.x0 - longest);
    common.y_lo = std::min(aligned_lookups->y_lo, base_.y0 - longest);
    common.x_hi = std::max(aligned_lookups->x_hi, base_.x0 + base_.nx - 1);
    common.y_hi = std::max(aligned_lookups->y_hi, base_.y0 + base_.ny - 1);
  }
  // A level depends on k only through its shortest window: levels of equal windows share one
  // copy, and (aligned: one box for all) a level of doubled windows comes from the one below.
  for (int k = 0; k <= max_level; ++k) {
    const int min_len = ((1 << k) - 1) / lattice_.subdivisions + 1;
    const Level* below = k > 0 ? &LevelAt(k - 1) : nullptr;
    if (below != nullptr && below->min_len == min_len) {
      level_slot_.push_back(level_slot_.back());
      continue;
    }
    if (below != nullptr && aligned_ && below->min_len * 2 == min_len) {
      unique_levels_.push_back(Doubled(*below, filter == Filter::kMax));
    } else {
      CellRange box = common;
      if (!aligned_) {
        box = CellRange{base_.x0 - min_len, base_.x0 + base_.nx - 1, base_.y0 - min_len,
                        base_.y0 + base_.ny - 1};
      }
      unique_levels_.push_back(Filtered(k, filter == Filter::kMax, box));
    }
    level_slot_.push_back(static_cast<int>(unique_levels_.size()) - 1);
  }
  if (aligned_) {
    const Level& lv = LevelAt(0);
    plane_ = ZeroedWords(static_cast<size_t>(lv.nx) * lv.ny);
    MarkCellsWritten(lv, 1, &plane_);
    // The level's written cells, and the rows among them holding any voxel (an empty plane:
    // none, lo above hi).
    plane_row_lo_ = lv.ny;
    plane_row_hi_ = -1;
    for (int y = lv.wy0; y <= lv.wy1; ++y) {
      std::uint64_t any = 0;
      for (int x = lv.wx0; x <= lv.wx1; ++x) {
        const size_t i = static_cast<size_t>(y) * lv.nx + x;
        plane_[i] = lv.data[4 * i];
        any |= plane_[i];
      }
      if (any != 0) {
        plane_row_lo_ = std::min(plane_row_lo_, y);
        plane_row_hi_ = y;
      }
    }
  }
}

int ColumnOccupancy::HitsGrouped(const CellTable& groups, int ix, int iy) const {
  assert(aligned_);
  const int mask = lattice_.subdivisions - 1;
  const Level& lv = LevelAt(0);  // the plane: level 0's one-cell windows, the cells' own voxels.
  // The runs' rows that can meet a cluster row (relative to the translation's cell row).
  const int row0 = ((iy & ~mask) >> shift_) - lv.y0;
  return RunPopcountSum(plane_.data(), PlaneBase(ix & ~mask, iy & ~mask), lv.nx, groups.words,
                        groups.runs, groups.mask_bytes, plane_row_lo_ - row0, plane_row_hi_ - row0);
}

void ColumnOccupancy::HitsGrouped4(const CellTable& groups, int ix, int iy, int d,
                                   int out[4]) const {
  assert(aligned_);
  const int mask = lattice_.subdivisions - 1;
  const Level& lv = LevelAt(0);
  const int row0 = ((iy & ~mask) >> shift_) - lv.y0;
  RunPopcountSum4(plane_.data(), PlaneBase(ix & ~mask, iy & ~mask), lv.nx, d,
                  static_cast<std::ptrdiff_t>(d) * lv.nx, groups.words, groups.runs,
                  groups.mask_bytes, plane_row_lo_ - row0 - d, plane_row_hi_ - row0, out);
}

int ColumnOccupancy::PairBound(const PairBlockTable& table, const std::uint64_t* masks, int a,
                               int b) const {
  assert(aligned_ && levels() > 1);
  const int mask = lattice_.subdivisions - 1;
  const Level& lv = LevelAt(1);
  return GatherPopcountSum(lv.data.data(), AlignedBase(a & ~mask, b & ~mask),
                           static_cast<std::ptrdiff_t>(lv.nx) * 4, table.cxe.data(),
                           table.cy.data(), masks, static_cast<int>(table.cxe.size()));
}

std::ptrdiff_t ColumnOccupancy::PlaneBase(int a, int b) const {
  const Level& lv = LevelAt(0);
  return static_cast<std::ptrdiff_t>((b >> shift_) - lv.y0) * lv.nx + ((a >> shift_) - lv.x0);
}

std::ptrdiff_t ColumnOccupancy::AlignedBase(int a, int b) const { return 4 * PlaneBase(a, b); }

void ColumnOccupancy::MarkCellsWritten(const Level& lv, size_t cell_words, ZeroedWords* data) {
  if (lv.wx1 < lv.wx0 || lv.wy1 < lv.wy0) return;
  data->MarkWritten((static_cast<size_t>(lv.wy0) * lv.nx + lv.wx0) * cell_words,
                    static_cast<size_t>(lv.wx1 - lv.wx0 + 1) * cell_words,
                    static_cast<size_t>(lv.nx) * cell_words,
                    static_cast<size_t>(lv.wy1 - lv.wy0 + 1));
}

ColumnOccupancy::Level ColumnOccupancy::Filtered(int k, bool max_filter,
                                                 const CellRange& box) const {
  const Grid& g0 = base_;
  Level lv;
  // A block of 2^k steps starting at sub-voxel offset r in [0, S) sweeps
  // floor((r + 2^k - 1) / S) + 1 cells: min_len at r = 0, at most one more.
  lv.min_len = ((1 << k) - 1) / lattice_.subdivisions + 1;
  lv.x0 = box.x_lo;
  lv.y0 = box.y_lo;
  lv.nx = box.x_hi - box.x_lo + 1;
  lv.ny = box.y_hi - box.y_lo + 1;
  const int words = words_;
  lv.data = ZeroedWords(static_cast<size_t>(lv.nx) * lv.ny * 4 * words);
  if (g0.nx == 0 || g0.ny == 0 || lv.nx <= 0 || lv.ny <= 0) return lv;
  if (lv.min_len == 1) {
    // Windows of one or two cells per axis: the cell, and the ones after it in x, y and both,
    // combined directly (cells outside the base are 0, as the sparse tables pad them).
    const auto row_of = [&](int y) -> const std::uint64_t* {
      const int gy = y + lv.y0 - g0.y0;
      return gy >= 0 && gy < g0.ny ? &g0.masks[static_cast<size_t>(gy) * g0.nx * words] : nullptr;
    };
    const auto at = [&](const std::uint64_t* row, int x, int w) -> std::uint64_t {
      const int gx = x + lv.x0 - g0.x0;
      return row != nullptr && gx >= 0 && gx < g0.nx ? row[static_cast<size_t>(gx) * words + w] : 0;
    };
    // Only cells with a base cell at them or one on can be non-zero.
    lv.wx0 = std::max(0, g0.x0 - lv.x0 - 1);
    lv.wx1 = std::min(lv.nx - 1, g0.x0 + g0.nx - 1 - lv.x0);
    lv.wy0 = std::max(0, g0.y0 - lv.y0 - 1);
    lv.wy1 = std::min(lv.ny - 1, g0.y0 + g0.ny - 1 - lv.y0);
    MarkCellsWritten(lv, 4 * static_cast<size_t>(words), &lv.data);
    for (int y = lv.wy0; y <= lv.wy1; ++y) {
      const std::uint64_t* r0 = row_of(y);
      const std::uint64_t* r1 = row_of(y + 1);
      if (r0 == nullptr && r1 == nullptr) continue;
      std::uint64_t* out = &lv.data[static_cast<size_t>(y) * lv.nx * 4 * words];
      for (int x = lv.wx0; x <= lv.wx1; ++x) {
        for (int w = 0; w < words; ++w) {
          const std::uint64_t a = at(r0, x, w), b = at(r0, x + 1, w);  // (x, y), (x + 1, y)
          const std::uint64_t c = at(r1, x, w), d = at(r1, x + 1, w);  // (x, y + 1), ...
          std::uint64_t* o = out + (static_cast<size_t>(x) * 4) * words + w;
          o[0] = a;
          o[words] = max_filter ? (a | c) : (a & c);
          o[2 * words] = max_filter ? (a | b) : (a & b);
          o[3 * words] = max_filter ? (a | b | c | d) : (a & b & c & d);
        }
      }
    }
    return lv;
  }
  // Longer windows reach further: the whole box is written.
  lv.wx0 = 0;
  lv.wx1 = lv.nx - 1;
  lv.wy0 = 0;
  lv.wy1 = lv.ny - 1;
  MarkCellsWritten(lv, 4 * static_cast<size_t>(words), &lv.data);
  std::vector<std::uint64_t> scratch;
  // Along x, per base row: tmp[e][(y * nx + x) * words + w], window min_len + e.
  std::vector<std::uint64_t> tmp[2];
  for (int e = 0; e < 2; ++e) {
    tmp[e].assign(static_cast<size_t>(g0.ny) * lv.nx * words, 0);
    for (int y = 0; y < g0.ny; ++y) {
      for (int w = 0; w < words; ++w) {
        Window1D(&g0.masks[static_cast<size_t>(y) * g0.nx * words + w], g0.nx, words, lv.x0 - g0.x0,
                 lv.min_len + e, max_filter, &tmp[e][static_cast<size_t>(y) * lv.nx * words + w],
                 lv.nx, words, &scratch);
      }
    }
  }
  // Along y into the interleaved level data.
  for (int ex = 0; ex < 2; ++ex) {
    for (int ey = 0; ey < 2; ++ey) {
      for (int x = 0; x < lv.nx; ++x) {
        for (int w = 0; w < words; ++w) {
          Window1D(&tmp[ex][static_cast<size_t>(x) * words + w], g0.ny,
                   static_cast<std::ptrdiff_t>(lv.nx) * words, lv.y0 - g0.y0, lv.min_len + ey,
                   max_filter, &lv.data[(static_cast<size_t>(x) * 4 + 2 * ex + ey) * words + w],
                   lv.ny, static_cast<std::ptrdiff_t>(lv.nx) * 4 * words, &scratch);
        }
      }
    }
  }
  return lv;
}

ColumnOccupancy::Level ColumnOccupancy::Doubled(const Level& below, bool max_filter) const {
  assert(words_ == 1);
  Level lv;
  lv.min_len = 2 * below.min_len;
  lv.x0 = below.x0;
  lv.y0 = below.y0;
  lv.nx = below.nx;
  lv.ny = below.ny;
  lv.data = ZeroedWords(below.data.size());
  if (below.wx1 < below.wx0 || below.wy1 < below.wy0) return lv;
  // A window is non-zero only where one of its four reads, len or len + 1 cells on, is (with
  // either filter): the written cells of the level below, extended back by len + 1.
  const int len = below.min_len;
  lv.wx0 = std::max(0, below.wx0 - len - 1);
  lv.wx1 = below.wx1;
  lv.wy0 = std::max(0, below.wy0 - len - 1);
  lv.wy1 = below.wy1;
  if (max_filter) {
    DoubleWindows<true>(below.data.data(), lv.nx, lv.ny, len, lv.wx0, lv.wx1, lv.wy0, lv.wy1,
                        lv.data.data());
  } else {
    DoubleWindows<false>(below.data.data(), lv.nx, lv.ny, len, lv.wx0, lv.wx1, lv.wy0, lv.wy1,
                         lv.data.data());
  }
  MarkCellsWritten(lv, 4, &lv.data);
  return lv;
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
  if (words_ == 1) {
    return HitsOneWord(acc_.data(), g.masks.data(), touched_.data(),
                       static_cast<int>(touched_.size()));
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
  if (!rotated.column_extent.empty()) {
    int out[4];
    ArcBounds(rotated, a, b, level, 1, out);
    return out[0];
  }
  return LowerBound(rotated, rotated.column_masks.data(), a, b, level);
}

// A theta block's column sweeps its square (side column_extent) plus the translation block:
// 2^level - 1 + extent steps beyond its corner, which the level sweeping that many holds (a
// window of the same start, no shorter). Past the top level the column's voxels all count.
// With `blocks` = 2 the four blocks of Bound4 (2^level a multiple of the subdivisions, so the
// windows are 2^level / S cells apart with equal lengths).
void ColumnOccupancy::ArcBounds(const RotatedTemplate& rotated, int a, int b, int level, int blocks,
                                int out[4]) const {
  const int n = static_cast<int>(rotated.column_q.size());
  const int top = levels() - 1;
  const int d = blocks == 2 ? (1 << level) / lattice_.subdivisions : 0;
  if (Aligned(rotated, a, b, level)) {
    thread_local std::vector<const std::uint64_t*> column_levels;
    column_levels.resize(static_cast<size_t>(n));
    for (int c = 0; c < n; ++c) {
      const int lvl = LevelSweeping((1 << level) - 1 + rotated.column_extent[c]);
      column_levels[c] = lvl > top ? nullptr : LevelAt(lvl).data.data();
    }
    const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(LevelAt(0).nx) * 4;
    SumArcsAligned(column_levels.data(), AlignedBase(a, b), row, 4 * d, d * row, blocks,
                   rotated.column_cxe.data(), rotated.column_cy.data(), rotated.column_masks.data(),
                   n, out);
    return;
  }
  int sums[4] = {0, 0, 0, 0};
  for (int c = 0; c < n; ++c) {
    const std::uint64_t* m = &rotated.column_masks[static_cast<size_t>(c) * words_];
    const int lvl = LevelSweeping((1 << level) - 1 + rotated.column_extent[c]);
    if (lvl > top) {
      const int all = SumArcColumn(m, m, words_);
      for (int k = 0; k < 4; ++k) sums[k] += all;
      continue;
    }
    const Level& lv = LevelAt(lvl);
    const int span = (1 << lvl) - 1;
    const int qa = rotated.column_q[c].x() + a;
    const int qb = rotated.column_q[c].y() + b;
    const int cx = FloorDivS(qa), cy = FloorDivS(qb);
    const int ex = FloorDivS(qa + span) - cx - (lv.min_len - 1);
    const int ey = FloorDivS(qb + span) - cy - (lv.min_len - 1);
    for (int i = 0; i < blocks; ++i) {
      const unsigned dx = static_cast<unsigned>(cx + i * d - lv.x0);
      if (dx >= static_cast<unsigned>(lv.nx)) continue;
      for (int j = 0; j < blocks; ++j) {
        const unsigned dy = static_cast<unsigned>(cy + j * d - lv.y0);
        if (dy >= static_cast<unsigned>(lv.ny)) continue;
        const std::uint64_t* cell =
            &lv.data[((static_cast<size_t>(dy) * lv.nx + dx) * 4 + 2 * ex + ey) * words_];
        sums[2 * i + j] += SumArcColumn(m, cell, words_);
      }
    }
  }
  for (int k = 0; k < 4; ++k) out[k] = sums[k];
}

int ColumnOccupancy::LowerBound(const RotatedTemplate& rotated, const std::uint64_t* masks, int a,
                                int b, int level) const {
  assert(level >= 0 && level < levels());
  assert(rotated.z_words == words_);
  assert(rotated.column_extent.empty());  // single rotations only.
  const Level& lv = LevelAt(level);
  if (Aligned(rotated, a, b, level)) {
    return GatherPopcountSum(lv.data.data(), AlignedBase(a, b),
                             static_cast<std::ptrdiff_t>(lv.nx) * 4, rotated.column_cxe.data(),
                             rotated.column_cy.data(), masks,
                             static_cast<int>(rotated.column_q.size()));
  }
  const int span = (1 << level) - 1;
  const int n = static_cast<int>(rotated.column_q.size());
  if (shift_ >= 0 && words_ == 1) {
    return SumOneWordPow2(lv.data.data(), lv.x0, lv.y0, lv.nx, lv.ny, shift_, lv.min_len - 1,
                          rotated.column_q.data(), masks, n, a, b, span);
  }
  return SumGeneric(lv.data.data(), lv.x0, lv.y0, lv.nx, lv.ny, lattice_.subdivisions,
                    lv.min_len - 1, words_, rotated.column_q.data(), masks, n, a, b, span);
}

void ColumnOccupancy::Bound4(const RotatedTemplate& rotated, int a, int b, int level,
                             int out[4]) const {
  assert(level >= 0 && level < levels());
  const int size = 1 << level;
  if (!rotated.column_extent.empty() && size % lattice_.subdivisions == 0) {
    ArcBounds(rotated, a, b, level, 2, out);
    return;
  }
  if (!rotated.column_extent.empty() || shift_ < 0 || words_ != 1 || size < lattice_.subdivisions) {
    for (int i = 0; i < 2; ++i) {
      for (int j = 0; j < 2; ++j)
        out[2 * i + j] = Bound(rotated, a + i * size, b + j * size, level);
    }
    return;
  }
  assert(rotated.z_words == words_);
  const Level& lv = LevelAt(level);
  if (Aligned(rotated, a, b, level)) {
    const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(lv.nx) * 4;
    const std::ptrdiff_t d = size >> shift_;
    GatherPopcountSum4(lv.data.data(), AlignedBase(a, b), row, 4 * d, d * row,
                       rotated.column_cxe.data(), rotated.column_cy.data(),
                       rotated.column_masks.data(), static_cast<int>(rotated.column_q.size()), out);
    return;
  }
  SumOneWordPow2x4(lv.data.data(), lv.x0, lv.y0, lv.nx, lv.ny, shift_, lv.min_len - 1,
                   rotated.column_q.data(), rotated.column_masks.data(),
                   static_cast<int>(rotated.column_q.size()), a, b, size - 1, size >> shift_, out);
}

std::vector<std::uint64_t> CellDisjointMasks(const RotatedTemplate& rotated, int subdivisions) {
  const int words = rotated.z_words;
  const int n = static_cast<int>(rotated.column_q.size());
  std::vector<std::uint64_t> out = rotated.column_masks;
  // Visit the columns by (qx, qy); the columns that can share a cell with column i and come
  // before it have qx in (qx_i - S, qx_i] and |qy - qy_i| < S.
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  const std::vector<Eigen::Vector2i>& q = rotated.column_q;
  const auto before = [&](int i, int j) {
    return q[i].x() != q[j].x() ? q[i].x() < q[j].x() : q[i].y() < q[j].y();
  };
  if (!std::is_sorted(order.begin(), order.end(), before)) {  // RotateTemplate sorts already.
    std::sort(order.begin(), order.end(), before);
  }
  int first = 0;  // first position (in `order`) with qx > qx_i - S.
  for (int pos = 0; pos < n; ++pos) {
    const int i = order[pos];
    while (q[order[first]].x() <= q[i].x() - subdivisions) ++first;
    for (int other = first; other < pos; ++other) {
      const int j = order[other];
      if (std::abs(q[j].y() - q[i].y()) >= subdivisions) continue;
      for (int w = 0; w < words; ++w) {
        out[static_cast<size_t>(i) * words + w] &= ~out[static_cast<size_t>(j) * words + w];
      }
    }
  }
  return out;
}

}  // namespace hpose
