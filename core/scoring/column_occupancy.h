#ifndef HPOSE_CORE_SCORING_COLUMN_OCCUPANCY_H_
#define HPOSE_CORE_SCORING_COLUMN_OCCUPANCY_H_

#include <cstdint>
#include <vector>

#include "core/scoring/pose_lattice.h"
#include "core/scoring/pose_scorer.h"

namespace hpose {

// A cluster's voxels as z bit masks per (x, y) cell, in the z frame of one template's columns
// (bit b of word w = z cell z_base + 64 w + b), plus a pyramid of max-filtered (OR-ed) copies
// for branch and bound over translations:
//   level k covers the translations [a, a + 2^k) x [b, b + 2^k) (lattice steps); its grid ORs
//   the cluster masks over the L_k x L_k cells such a block can move a column across, with
//   L_k = floor((2^k + S - 2) / S) + 1, S = lattice subdivisions.
// Cluster voxels outside the template's z range can never be covered and are left out of the
// masks (they still count in the score's denominator).
//
// With Filter::kMin the pyramid ANDs instead (cells outside the voxels count as empty), so
// Bound() is a lower bound of Hits over the block: used for free-space cells, which count
// against a pose.
class ColumnOccupancy {
 public:
  enum class Filter { kMax, kMin };

  ColumnOccupancy(const ClusterVoxels& cluster, const PoseLattice& lattice, int z_base, int z_words,
                  int max_level, Filter filter = Filter::kMax);

  // Exact number of distinct cluster voxels covered by `rotated` at (ix, iy): equal to
  // PoseScorer::Hits for the same pose. Not thread-safe (scratch space).
  int Hits(const RotatedTemplate& rotated, int ix, int iy) const;

  // An upper bound (kMax) or lower bound (kMin) of Hits over every translation in
  // [a, a + 2^level) x [b, b + 2^level). level in [0, max_level]; at level 0 the
  // bound counts every column separately (no de-duplication), an upper bound for kMax only.
  int Bound(const RotatedTemplate& rotated, int a, int b, int level) const;

  int max_level() const { return static_cast<int>(levels_.size()) - 1; }

 private:
  struct Grid {
    int x0 = 0, y0 = 0, nx = 0, ny = 0;
    std::vector<std::uint64_t> masks;  // nx * ny * words.
  };
  // Column (qx, qy) + translation -> cell index in `g`, or -1 outside.
  int Index(const Grid& g, int qx, int qy, int a, int b) const;

  PoseLattice lattice_;
  int shift_ = -1;  // log2(subdivisions) when a power of two.
  int words_ = 1;
  std::vector<Grid> levels_;  // levels_[0]: the plain occupancy.
  mutable std::vector<std::uint32_t> stamp_;
  mutable std::vector<std::uint64_t> acc_;
  mutable std::vector<int> touched_;
  mutable std::uint32_t current_stamp_ = 0;
};

}  // namespace hpose

#endif  // HPOSE_CORE_SCORING_COLUMN_OCCUPANCY_H_
