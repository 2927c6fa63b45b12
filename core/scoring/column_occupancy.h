#ifndef HPOSE_CORE_SCORING_COLUMN_OCCUPANCY_H_
#define HPOSE_CORE_SCORING_COLUMN_OCCUPANCY_H_

#include <cstdint>
#include <vector>

#include "core/scoring/pose_lattice.h"
#include "core/scoring/pose_scorer.h"
#include "core/scoring/zeroed_words.h"

namespace hpose {

// A cluster's voxels as z bit masks per (x, y) cell, in the z frame of one template's columns
// (bit b of word w = z cell z_base + 64 w + b), plus a pyramid of filtered copies for branch and
// bound over translations. Level k covers the translations [a, a + 2^k) x [b, b + 2^k) (lattice
// steps). Over such a block a template column with sub-voxel coordinate q reaches exactly the
// cells floor_div(q + a, S) .. floor_div(q + a + 2^k - 1, S) (S = subdivisions): a window of
// L_min or L_min + 1 cells per axis, depending on q. Each level keeps the cluster masks OR-ed
// (Filter::kMax: an upper bound of the cells a column can cover) over both window lengths in x
// and y, and every column looks up the window it really sweeps.
// Cluster voxels outside the template's z range can never be covered and are left out of the
// masks (they still count in the score's denominator).
//
// With Filter::kMin the windows AND instead (cells outside the voxels count as empty): used for
// free-space cells, which count against a pose. LowerBound() with CellDisjointMasks() is then a
// lower bound of Hits over the block.
class ColumnOccupancy {
 public:
  enum class Filter { kMax, kMin };

  // Cells (inclusive) where bound windows may start: with a power-of-two subdivision, one word
  // per column and such a range, every level covers it with one common layout, and bounds of
  // blocks of at least S steps starting at multiples of S (S = subdivisions) take the aligned
  // path (RotatedTemplate::column_cxe: no per-column index arithmetic or range checks).
  struct CellRange {
    int x_lo = 0, x_hi = -1, y_lo = 0, y_hi = -1;
  };

  ColumnOccupancy(const ClusterVoxels& cluster, const PoseLattice& lattice, int z_base, int z_words,
                  int max_level, Filter filter = Filter::kMax,
                  const CellRange* aligned_lookups = nullptr);

  // Exact number of distinct cluster voxels covered by `rotated` at (ix, iy): equal to
  // PoseScorer::Hits for the same pose. Not thread-safe (scratch space).
  int Hits(const RotatedTemplate& rotated, int ix, int iy) const;

  // Sum over the columns of the voxels each column meets in its window over every translation
  // in [a, a + 2^level) x [b, b + 2^level), level in [0, max_level]. With kMax it is an upper
  // bound of Hits over the block, also over the rotations of a theta block
  // (TemplateRotations::GetBlock: each column then sweeps its square of sub-voxel coordinates
  // too, through a higher level's window); a cell that two columns reach counts twice. Levels
  // above max_level make a column count all its voxels. With kMin it is NOT a lower bound in
  // general (two columns landing in one cell count twice): use LowerBound for that.
  int Bound(const RotatedTemplate& rotated, int a, int b, int level) const;

  // The same sum with `masks` (z_words per column of `rotated`) in place of the column masks.
  // With kMin and masks = CellDisjointMasks(rotated, subdivisions): a lower bound of Hits of
  // `rotated` (a single rotation) at every translation of the block.
  int LowerBound(const RotatedTemplate& rotated, const std::uint64_t* masks, int a, int b,
                 int level) const;

  // Bound() of the four blocks of 2^level steps starting at (a + i 2^level, b + j 2^level),
  // i, j in {0, 1}, into out[2 i + j]: the four children of a block of level + 1. Equal to four
  // Bound calls, in about the time of two when 2^level is a multiple of the subdivisions (a
  // column then sweeps windows of the same length in all four, one lookup apart).
  void Bound4(const RotatedTemplate& rotated, int a, int b, int level, int out[4]) const;

  // Hits of a rotation at (ix, iy) from its CellGroups for the residue of (ix, iy)
  // (TemplateRotations::Groups): equal to Hits, without scratch space, in the aligned layout
  // (aligned() only; the cells of every group must lie in the lookup range).
  int HitsGrouped(const CellTable& groups, int ix, int iy) const;
  int HitsGrouped(const CellGroups& groups, int ix, int iy) const {
    return HitsGrouped(groups.table(), ix, iy);
  }
  // HitsGrouped at (ix + i d S, iy + j d S), i, j in {0, 1}, into out[2 i + j] (S = the
  // subdivisions): one pass over the groups for four translations a whole number of cells apart.
  void HitsGrouped4(const CellTable& groups, int ix, int iy, int d, int out[4]) const;
  bool aligned() const { return aligned_; }
  // The bound of a block of 2 steps (level 1) at (a, b), with the rotation's PairBlockTable for
  // the residue of (a, b) and the rotation's masks (or cell-disjoint masks for a lower bound):
  // equal to Bound / LowerBound at level 1, in the aligned layout (aligned(), S >= 4).
  int PairBound(const PairBlockTable& table, const std::uint64_t* masks, int a, int b) const;

  int max_level() const { return levels() - 1; }

 private:
  // Level k: every cell (x, y) of the level's box holds four masks, the kMax/kMin combination
  // of the base over the windows [x, x + len_x) x [y, y + len_y) for len_x, len_y in
  // {min_len, min_len + 1}, interleaved: data[((dy * nx + dx) * 4 + 2 ex + ey) * words + w].
  // Cells outside the level's written rectangle [wx0, wx1] x [wy0, wy1] (box-relative, empty
  // when wx1 < wx0) hold 0: a box ten to a hundred times the cluster's area is not written.
  struct Level {
    int min_len = 1;  // shortest window (cells) a column sweeps at this level.
    int x0 = 0, y0 = 0, nx = 0, ny = 0;
    int wx0 = 0, wx1 = -1, wy0 = 0, wy1 = -1;
    ZeroedWords data;
  };
  struct Grid {
    int x0 = 0, y0 = 0, nx = 0, ny = 0;
    std::vector<std::uint64_t> masks;  // nx * ny * words.
  };
  Level Filtered(int level, bool max_filter, const CellRange& box) const;
  // The level of windows twice as long as `below`'s, from `below` (same box; one word per cell).
  Level Doubled(const Level& below, bool max_filter) const;
  // Declares the level's written cells, `cell_words` words each in `data` (its data, or the
  // plane: one word a cell), to the pool they go back to.
  static void MarkCellsWritten(const Level& lv, size_t cell_words, ZeroedWords* data);
  const Level& LevelAt(int k) const { return unique_levels_[level_slot_[k]]; }
  int levels() const { return static_cast<int>(level_slot_.size()); }
  // Whether a block of 2^level steps at (a, b) can take the aligned path with `rotated`.
  bool Aligned(const RotatedTemplate& rotated, int a, int b, int level) const {
    return aligned_ && level >= shift_ && ((a | b) & (lattice_.subdivisions - 1)) == 0 &&
           !rotated.column_cxe.empty();
  }
  // Index of the cell holding the windows of cell offset (0, 0) for a block at (a, b).
  std::ptrdiff_t AlignedBase(int a, int b) const;
  // The same cell's index in plane_.
  std::ptrdiff_t PlaneBase(int a, int b) const;
  // Bound (blocks 1: out[0]) or Bound4 (blocks 2) of a theta block's columns.
  void ArcBounds(const RotatedTemplate& rotated, int a, int b, int level, int blocks,
                 int out[4]) const;
  int FloorDivS(int v) const;

  PoseLattice lattice_;
  int shift_ = -1;  // log2(subdivisions) when a power of two.
  int words_ = 1;
  Grid base_;
  std::vector<Level> unique_levels_;
  std::vector<int> level_slot_;  // level k is unique_levels_[level_slot_[k]].
  bool aligned_ = false;         // every level shares the layout of level 0 over the lookup range.
  // Aligned only: level 0's own cells (entry 0) as one word per cell, same box, row by row: the
  // plane HitsGrouped reads runs of cells from.
  ZeroedWords plane_;
  // The first and last row of plane_ with a non-zero word: runs of cells outside them add 0.
  int plane_row_lo_ = 0, plane_row_hi_ = -1;
  mutable std::vector<std::uint32_t> stamp_;
  mutable std::vector<std::uint64_t> acc_;
  mutable std::vector<int> touched_;
  mutable std::uint32_t current_stamp_ = 0;
};

// Column masks of `rotated` (z_words per column, same order) with the z bits removed that an
// earlier column able to share a placed cell with it already holds: columns whose sub-voxel
// coordinates differ by less than `subdivisions` in both x and y can land in one cell, and
// counting such a voxel once per column would overcount it. Every remaining voxel is a voxel of
// the template, and no two columns that can share a cell share a z bit, so summing them over
// any cells they land in never counts a placed voxel twice.
std::vector<std::uint64_t> CellDisjointMasks(const RotatedTemplate& rotated, int subdivisions);

}  // namespace hpose

#endif  // HPOSE_CORE_SCORING_COLUMN_OCCUPANCY_H_
