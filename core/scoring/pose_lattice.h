#ifndef HPOSE_CORE_SCORING_POSE_LATTICE_H_
#define HPOSE_CORE_SCORING_POSE_LATTICE_H_

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/common/pose2d.h"
#include "core/common/status.h"
#include "core/scoring/gather_sums.h"
#include "core/scoring/table_arena.h"
#include "core/templates/voxel_template.h"

namespace hpose {

// The discrete set of poses every search evaluates, and the exact placement semantics that
// every scorer shares (so a fast scorer can equal the reference one bit for bit):
//   translation (x, y) = (ix, iy) * step,  step = resolution / subdivisions;
//   theta = itheta * 2 pi / angle_steps,  itheta in [0, angle_steps).
// A template point p (one per voxel: VoxelTemplate::VoxelSurfaceCentroids, the mean of the
// body's surface inside the voxel, so rotated copies do not alias on the grid the way voxel
// centres do), rotated by theta in double precision, is first quantised to the
// sub-voxel grid, q = floor(R p * subdivisions / resolution) (x and y), and the placed cell is
// cell = floor_div(q + (ix, iy), subdivisions), z cell = floor(p.z / resolution).
// Mathematically this is floor((R p + t) / resolution); the quantisation of R p is the only
// rounding, done once per (template, theta), so integer translations are exact.
struct PoseLattice {
  double resolution_m = 0.016;  // scoring voxel edge (SPEC §1: 16 mm).
  int subdivisions = 4;         // translation step = resolution / subdivisions (4 mm).
  int angle_steps = 360;        // theta step = 360 deg / angle_steps (1 deg).

  double step_m() const { return resolution_m / subdivisions; }
  double angle_step_rad() const { return 2.0 * kPi / angle_steps; }

  // Checks resolution in [1 mm, 0.5 m], subdivisions in [1, 64], angle_steps in [4, 36000].
  Status Validate() const;
};

struct LatticePose {
  int ix = 0;
  int iy = 0;
  int itheta = 0;  // in [0, angle_steps).

  bool operator==(const LatticePose& o) const {
    return ix == o.ix && iy == o.iy && itheta == o.itheta;
  }
};

// The metric pose of a lattice pose; theta normalised to (-pi, pi].
Pose2D ToPose(const PoseLattice& lattice, const LatticePose& p);
// The nearest lattice pose to a metric pose.
LatticePose NearestLatticePose(const PoseLattice& lattice, const Pose2D& pose);
// Wraps any integer angle index into [0, angle_steps).
int WrapAngleIndex(const PoseLattice& lattice, int itheta);

inline int FloorDiv(int a, int b) {
  const int q = a / b;
  return (a % b != 0 && ((a < 0) != (b < 0))) ? q - 1 : q;
}

// Integer voxel cell of a point: floor(p * (1 / resolution)) per axis, computed exactly as
// OctoMap's coordToKey does (minus its key offset).
Eigen::Vector3i CellOf(const Eigen::Vector3f& p, double resolution_m);

// A template rotated by one lattice angle: per voxel the sub-voxel x, y (q) and the z cell.
struct RotatedTemplate {
  int itheta = 0;
  // (qx, qy, cz) per template voxel, from RotatePoints and RotateTemplate (the reference). The
  // rotations of a TemplateRotations hold the column view only: ForEachPlacedVoxel reads either.
  std::vector<Eigen::Vector3i> sub_cells;
  Eigen::Vector2i q_min = Eigen::Vector2i::Zero();  // bounds of qx, qy.
  Eigen::Vector2i q_max = Eigen::Vector2i::Zero();

  // Column view: the voxels grouped by equal (qx, qy). Every voxel of a column lands in the
  // same (x, y) cell for any translation, so a column is scored with one z bit mask. Bit b of
  // word w of a column's mask is z cell z_base + 64 w + b.
  int z_base = 0;                           // lowest z cell of the template.
  int z_words = 0;                          // 64-bit words per column mask.
  std::vector<Eigen::Vector2i> column_q;    // (qx, qy) per column, sorted.
  std::vector<std::uint64_t> column_masks;  // z_words per column.
  // Theta blocks only (TemplateRotations::GetBlock with level > 0): over the block's rotations
  // the template columns gathered in column c lie at sub-voxel coordinates within
  // [column_q[c], column_q[c] + column_extent[c]] on both axes. Empty for single rotations
  // (every extent 0).
  std::vector<int> column_extent;
  // With a power-of-two subdivision S, per column: the cell of column_q (q >> log2 S) as cy and
  // 4 cx + e, e = 2 [qx mod S != 0] + [qy mod S != 0]: for a translation block of at least S
  // steps starting at a multiple of S, the window the column sweeps starts at its cell plus the
  // block's and is one cell longer per axis where e says (ColumnOccupancy's aligned path).
  std::vector<std::int32_t> column_cxe;
  std::vector<std::int32_t> column_cy;
};

// Calls f(sub_cell) once for every distinct (qx, qy, cz) of a single rotation (not a theta block),
// read from its column view: the cells of its sub_cells, each once.
template <typename F>
void ForEachPlacedVoxel(const RotatedTemplate& r, F&& f) {
  for (size_t c = 0; c < r.column_q.size(); ++c) {
    const Eigen::Vector2i& q = r.column_q[c];
    for (int w = 0; w < r.z_words; ++w) {
      for (std::uint64_t m = r.column_masks[c * r.z_words + w]; m != 0; m &= m - 1) {
        f(Eigen::Vector3i(q.x(), q.y(), r.z_base + 64 * w + __builtin_ctzll(m)));
      }
    }
  }
}

RotatedTemplate RotateTemplate(const VoxelTemplate& tpl, const PoseLattice& lattice, int itheta);
// The same for the template points `points` (VoxelSurfaceCentroids of a template).
RotatedTemplate RotatePoints(const std::vector<Eigen::Vector3f>& points, const PoseLattice& lattice,
                             int itheta);

// The placed cell of one rotated template voxel at translation (ix, iy).
inline Eigen::Vector3i PlacedCell(const Eigen::Vector3i& sub_cell, int ix, int iy,
                                  int subdivisions) {
  return Eigen::Vector3i(FloorDiv(sub_cell.x() + ix, subdivisions),
                         FloorDiv(sub_cell.y() + iy, subdivisions), sub_cell.z());
}

// What a search reads of a CellGroups: its words (the headers, a sentinel, then the masks), how
// many runs, how many of its first words a prefetch asks for, and how many bytes a mask.
struct CellTable {
  // The words a prefetch of a table's start asks for: its words in whole cache lines, at most 8
  // lines (the hardware streams the rest).
  static constexpr int kPrefetchLines = 8;
  static int PrefetchWords(std::size_t words) {
    return static_cast<int>(std::min<std::size_t>((words + 7) / 8, kPrefetchLines) * 8);
  }
  const std::uint64_t* words = nullptr;
  int runs = 0;
  int prefetch_words = 0;
  int mask_bytes = 8;
};

// A rotation's columns grouped by the cell they land in at translations with one residue
// (ix mod S, iy mod S), S a power of two: per group the cell offset (cx, cy; added to the
// translation's cell (ix >> log2 S, iy >> log2 S) minus the residue's) and the union of the
// group's masks. Each cell appears once, so summing a group's voxels in its cell counts every
// covered voxel exactly once: the exact hits (ColumnOccupancy::HitsGrouped). The cells are kept
// row by row in runs of at most kMaxRun consecutive cells of one row: run r covers cells
// (cx + i, cy) for i below its length, and the masks follow the headers, one per cell, run after
// run, in mask_bytes bytes each (HitsGrouped reads a run's masks as consecutive bytes; the
// layout, a sentinel and padding included, is gather_sums.h's).
struct CellGroups {
  static constexpr int kMaxRun = 8;
  // The runs' 4-byte headers (RunHeader, gather_sums.h), a sentinel, then every cell's mask, run
  // after run, and padding: one array whose headers load independently of each other.
  TableWords words;
  int runs = 0;
  int cell_count = 0;
  int mask_bytes = 8;  // the template's: enough for its highest z bit.

  int cells() const { return cell_count; }
  CellTable table() const {
    return {words.data(), runs, CellTable::PrefetchWords(words.size()), mask_bytes};
  }
  std::uint64_t mask(int cell) const {
    return LoadRunMask(RunMasks(words.data(), runs) + static_cast<size_t>(cell) * mask_bytes,
                       mask_bytes);
  }
  // Calls f(cx, cy, mask) for every cell, in order.
  template <typename F>
  void ForEachCell(F&& f) const {
    int k = 0;
    for (int r = 0; r < runs; ++r) {
      const RunHeaderWord h = RunHeaderAt(words.data(), r);
      const int cx = RunHeaderX(h), cy = RunHeaderY(h), len = RunHeaderLength(h);
      for (int i = 0; i < len; ++i) f(cx + i, cy, mask(k++));
    }
  }
};

// A rotation's columns (same order as column_q) for translation blocks of 2 steps starting at
// residue (ra, rb) (even, below S): per column 4 cx + 2 ex + ey and cy, the window's first
// cell (added to the aligned base of the block's translation minus the residue) and whether it
// is one cell longer per axis (ColumnOccupancy::PairBound).
struct PairBlockTable {
  std::vector<std::int32_t> cxe;
  std::vector<std::int32_t> cy;
};

// All angle_steps rotations of one template under one lattice, computed once at construction
// (360 rotations of a few thousand voxels: a few ms, a few MB), plus a pyramid over theta for
// branch and bound: the block of level t starting at itheta0 (a multiple of 2^t) holds, per
// template column, the arc it sweeps over rotations itheta0 .. itheta0 + 2^t - 1 as the
// smallest square of sub-voxel coordinates holding it (corner column_q, side column_extent),
// columns with equal squares merged. Every voxel of every rotation in the block then lies in
// exactly one block column's square with its z bit set, and counts once in a bound over the
// block, however far it moves.
// Immutable, so shareable between threads.
class TemplateRotations {
 public:
  static constexpr int kThetaLevels = 5;  // blocks of up to 16 angle steps.

  TemplateRotations(const VoxelTemplate& tpl, const PoseLattice& lattice);
  // The same for the template points `points` (VoxelSurfaceCentroids of a template).
  TemplateRotations(std::string name, double height_m, const std::vector<Eigen::Vector3f>& points,
                    const PoseLattice& lattice);
  // itheta in [0, angle_steps).
  const RotatedTemplate& Get(int itheta) const { return rotations_[itheta]; }
  // The columns of the theta block (level, itheta0); level 0 is Get(itheta0). Only the column
  // view (column_q, column_masks, column_extent, z_base, z_words) is filled for level > 0.
  const RotatedTemplate& GetBlock(int level, int itheta0) const;
  // The largest column_extent of any theta block (0 without blocks).
  int max_block_extent() const { return max_block_extent_; }
  // The largest column_extent of the theta blocks of level tlevel (0 for tlevel 0): how far the
  // template's rim moves over 2^tlevel headings, in sub-voxel steps.
  int block_extent(int tlevel) const {
    return tlevel <= 0 || level_extent_.empty()
               ? 0
               : level_extent_[std::min<size_t>(tlevel, level_extent_.size()) - 1];
  }
  // CellGroups of rotation itheta for translations of residue (rx, ry), made on first use
  // (thread-safe); only for a power-of-two subdivision and one-word columns
  // (has_cell_groups()).
  const CellGroups& Groups(int itheta, int rx, int ry) const;
  bool has_cell_groups() const { return shift_ >= 0 && z_words_ == 1; }
  // PairBlockTable of rotation itheta for residue (ra, rb), both even and below S (S >= 4);
  // made on first use with the CellGroups.
  const PairBlockTable& PairTable(int itheta, int ra, int rb) const;
  // Levels of translation blocks with swept cell groups (SweptGroups): 1 .. kSweptLevels.
  static constexpr int kSweptLevels = 4;
  // The cells rotation itheta reaches over a translation block of 2^level steps per side
  // (level in [1, kSweptLevels]) whose first step has residue (ra, rb) (multiples of
  // min(2^level, S), below S), as CellGroups relative to the block's first cell: per cell the
  // union of the masks of every column landing in it at some translation of the block. Summed
  // over cluster cells (ColumnOccupancy::HitsGrouped), every cluster voxel the template can
  // cover anywhere in the block counts once: an upper bound of the hits over the block that,
  // unlike the column bound, never counts a voxel twice. Made on first use (thread-safe), with
  // the same conditions as Groups.
  const CellGroups& SweptGroups(int itheta, int level, int ra, int rb) const;
  // SweptGroups of the theta block (tlevel, itheta0) of GetBlock (tlevel below kThetaLevels,
  // itheta0 a multiple of 2^tlevel): per cell the union of the masks of its rotations' tables,
  // so an upper bound of the hits of every pose of the block's rotations and translations that
  // counts each cluster voxel once. Level 0 (single translations; residues (ra, rb) below S)
  // unites the rotations' Groups. tlevel 0 is SweptGroups (Groups at level 0). Made on first
  // use (thread-safe).
  const CellGroups& SweptBlockGroups(int tlevel, int itheta0, int level, int ra, int rb) const;
  // The cells every rotation of the theta block covers at a translation of residue (ra, rb)
  // (below S), each with the z bits all of them set there (CellGroups, as Groups): voxels every
  // pose of the block at that translation places, so their free-space hits are a lower bound of
  // each pose's. tlevel 0 is Groups. Made with SweptBlockGroups.
  const CellGroups& CommonBlockGroups(int tlevel, int itheta0, int ra, int rb) const;
  // The cells every pose of the theta block (tlevel, itheta0; tlevel 0: rotation itheta0)
  // covers at all four translations of a block of 2 x 2 steps whose first step has residue
  // (ra, rb) (multiples of min(2, S) below S), as SweptGroups(itheta, 1, ra, rb) relative to the
  // block's first cell, each with the z bits all of those poses set there: voxels every pose of
  // the block places, so their free-space hits are a lower bound of each pose's. Made on first
  // use (thread-safe), every residue of a block at once.
  const CellGroups& CommonPairGroups(int tlevel, int itheta0, int ra, int rb) const;
  // SweptBlockGroups and CommonBlockGroups as their CellTable, through a directory of every
  // table's words and run count filled as the tables are made: a made table costs one load of
  // 8 bytes (the search asks for one per bound) instead of its once_flag's and its header's,
  // in two other places. Made on first use as the others (thread-safe).
  CellTable SweptTable(int tlevel, int itheta0, int level, int ra, int rb) const {
    TableRef& ref = table_refs_[TableId(tlevel, itheta0, BlockSweptIndexOf(level, ra, rb))];
    const CellTable made = Made(ref);
    if (made.words != nullptr) return made;
    return Publish(ref, SweptBlockGroups(tlevel, itheta0, level, ra, rb));
  }
  CellTable CommonTable(int tlevel, int itheta0, int ra, int rb) const {
    if (tlevel == 0) return SweptTable(0, itheta0, 0, ra, rb);  // Groups either way.
    TableRef& ref = table_refs_[TableId(tlevel, itheta0, CommonIndex(ra, rb))];
    const CellTable made = Made(ref);
    if (made.words != nullptr) return made;
    return Publish(ref, CommonBlockGroups(tlevel, itheta0, ra, rb));
  }
  // CommonPairGroups as its CellTable, through a directory of its own as SweptTable's.
  CellTable CommonPairTable(int tlevel, int itheta0, int ra, int rb) const {
    TableRef& ref = pair_refs_[PairId(tlevel, itheta0, ra, rb)];
    const CellTable made = Made(ref);
    if (made.words != nullptr) return made;
    return Publish(ref, CommonPairGroups(tlevel, itheta0, ra, rb));
  }
  // The same tables when they are made already, else an empty CellTable (no words, nothing to
  // prefetch), without making them: for prefetching tables a search may not read.
  CellTable SweptTableIfMade(int tlevel, int itheta0, int level, int ra, int rb) const {
    return Made(table_refs_[TableId(tlevel, itheta0, BlockSweptIndexOf(level, ra, rb))]);
  }
  CellTable CommonTableIfMade(int tlevel, int itheta0, int ra, int rb) const {
    if (tlevel == 0) return SweptTableIfMade(0, itheta0, 0, ra, rb);
    return Made(table_refs_[TableId(tlevel, itheta0, CommonIndex(ra, rb))]);
  }
  CellTable CommonPairTableIfMade(int tlevel, int itheta0, int ra, int rb) const {
    return Made(pair_refs_[PairId(tlevel, itheta0, ra, rb)]);
  }
  // Makes now every table the getters above make on first use (Groups, PairTable, SweptGroups,
  // CommonPairGroups, and SweptBlockGroups, CommonBlockGroups and CommonPairGroups of theta
  // levels up to max_tlevel), so that no search pays for them, each entered in the directory
  // (the *IfMade getters find it); a no-op without cell groups.
  // Thread-safe; rotations [begin, end) only, so that threads can share the work.
  void MakeTables(int max_tlevel, int begin, int end) const;
  // A template taller than 64 z cells (z_words() > 1) has none of the cell tables above; its
  // slabs do: its points cut at every 64th z cell from its lowest, each run of 64 cells a
  // TemplateRotations of its own (one-word columns, the same columns' (x, y)). The slabs' cells
  // are disjoint, so a pose's hits are the sum of its slabs' hits, and a sum of their bounds
  // bounds it. Empty for one-word templates and without a power-of-two subdivision. A slab's
  // rotations hold the column view only, as the template's own do.
  const std::vector<std::unique_ptr<TemplateRotations>>& slabs() const { return slabs_; }
  int z_words() const { return z_words_; }
  // The bytes of a cell table's mask (CellGroups::mask_bytes): those of the highest z bit any
  // column sets.
  int mask_bytes() const { return mask_bytes_; }
  // CellDisjointMasks of rotation itheta (for free-space lower bounds), made once.
  const std::vector<std::uint64_t>& DisjointMasks(int itheta) const { return disjoint_[itheta]; }
  // The range of column_q over every rotation and block (sub-voxel steps).
  const Eigen::Vector2i& column_q_min() const { return column_q_min_; }
  const Eigen::Vector2i& column_q_max() const { return column_q_max_; }
  const std::string& name() const { return name_; }
  double height_m() const { return height_m_; }
  // How far rotation 0's voxels reach from the origin horizontally: the farthest corner (q or
  // q + 1 per axis, in metres) of any of its sub-voxel cells; 0 for a slab.
  double rim_radius_m() const { return rim_radius_m_; }
  // The template points it was made from (one per template voxel); 0 for a slab.
  std::size_t voxels() const { return voxels_; }
  const PoseLattice& lattice() const { return lattice_; }

 private:
  // The memory of the cell tables' words (CellGroups), in huge pages where the system allows.
  // Declared first: destroyed last, after every container holding its memory.
  std::unique_ptr<TableArena> arena_ = std::make_unique<TableArena>();
  // CommonPairGroups' words, apart from the bounds' tables (which the searches read far more
  // often), so that those stay on as few pages as before.
  std::unique_ptr<TableArena> pair_arena_ = std::make_unique<TableArena>();
  std::string name_;
  double height_m_ = 0.0;
  double rim_radius_m_ = 0.0;
  std::size_t voxels_ = 0;
  PoseLattice lattice_;
  std::vector<RotatedTemplate> rotations_;
  // blocks_[level - 1][itheta0 >> level] for level in [1, kThetaLevels).
  std::vector<std::vector<RotatedTemplate>> blocks_;
  int max_block_extent_ = 0;
  std::vector<int> level_extent_;                     // block_extent per theta level from 1.
  std::vector<std::vector<std::uint64_t>> disjoint_;  // per rotation.
  int shift_ = -1;                                    // log2(subdivisions) when a power of two.
  int z_words_ = 0;                                   // words per column.
  int mask_bytes_ = 8;  // the cell tables' mask width: the bytes of the highest z bit.
  // Per rotation, S^2 residues of CellGroups, made once each on first use.
  mutable std::vector<std::vector<CellGroups>> groups_;
  mutable std::vector<std::vector<PairBlockTable>> pair_tables_;  // (S/2)^2 per rotation.
  mutable std::unique_ptr<std::once_flag[]> groups_once_;
  // Per rotation: for each level 1 .. kSweptLevels its residues' SweptGroups.
  mutable std::vector<std::vector<CellGroups>> swept_;
  mutable std::unique_ptr<std::once_flag[]> swept_once_;
  // Per theta level t in [1, kThetaLevels), block after block (itheta0 >> t), block_tables_
  // each: SweptBlockGroups, level 0's residues first, then in the order of swept_; then
  // CommonBlockGroups per residue. Each made on first use, with a once_flag of its own.
  mutable std::vector<std::vector<CellGroups>> swept_blocks_;
  mutable std::vector<std::unique_ptr<std::once_flag[]>> swept_blocks_once_;
  size_t block_tables_ = 0;
  // CommonPairGroups per theta level t (0 .. kThetaLevels - 1) and block (itheta0 >> t), its
  // residues in the order of swept_'s level 1, made together under the block's once_flag.
  mutable std::vector<std::vector<std::vector<CellGroups>>> common_pairs_;
  mutable std::vector<std::unique_ptr<std::once_flag[]>> common_pairs_once_;
  // CommonPairTable's directory: per theta level t from pair_offset_[t], block after block,
  // pair_tables_per_block_ each.
  std::size_t pair_tables_per_block_ = 0;
  std::size_t pair_offset_[kThetaLevels] = {};
  // The directory of SweptTable and CommonTable: per theta level t (0 .. kThetaLevels - 1; level
  // 0 holds Groups and SweptGroups) from table_offset_[t], block after block, block_tables_ each
  // in the order of swept_blocks_. An entry is 0 until its table is made (every table has words:
  // an empty one its sentinel and padding), then one word (a search reads one per bound, at
  // scattered places of a directory of about half a MB, so its size decides what stays cached):
  // the words' address (cache-line aligned, below 2^47) with, in its low 6 bits, how many of
  // the first 8 cache lines the table fills (what a prefetch asks for), and the run count in the
  // top 17 bits. A table that does not fit so (more runs, or words elsewhere) is not entered:
  // each use finds it through its once_flag.
  using TableRef = std::atomic<std::uint64_t>;
  static constexpr int kRunShift = 47;
  static constexpr std::uint64_t kAddressMask = ((std::uint64_t{1} << kRunShift) - 1) & ~63ULL;
  std::unique_ptr<TableRef[]> table_refs_;
  std::unique_ptr<TableRef[]> pair_refs_;
  std::size_t table_offset_[kThetaLevels] = {};
  // BlockSweptIndex of (level, ra, rb) at [(level * S + ra) * S + rb], level 0 .. kSweptLevels.
  std::vector<std::uint16_t> block_index_;
  Eigen::Vector2i column_q_min_ = Eigen::Vector2i::Zero();
  Eigen::Vector2i column_q_max_ = Eigen::Vector2i::Zero();
  std::vector<std::unique_ptr<TemplateRotations>> slabs_;

  // Slab `word` of `parent` (z_words() > 1), its lowest z cell `offset` cells above the word's
  // first: the parent's rotations and theta blocks cut to the columns with a bit in the word
  // (what rotating the slab's own points would make, without the sort that costs).
  TemplateRotations(const TemplateRotations& parent, int word, int offset);
  // The rest of a construction once rotations_, blocks_, level_extent_, max_block_extent_ and
  // z_words_ are set: the cell tables' columns, the range of column_q, the free-space masks and
  // the slots of the tables made on first use.
  void PrepareTables();
  std::size_t TableId(int tlevel, int itheta0, std::size_t index) const {
    return table_offset_[tlevel] + (static_cast<std::size_t>(itheta0) >> tlevel) * block_tables_ +
           index;
  }
  // Where CommonTable's entry lies among a block's.
  std::size_t CommonIndex(int ra, int rb) const {
    return block_tables_ - static_cast<std::size_t>(1 << (2 * shift_)) +
           (static_cast<std::size_t>(ra) << shift_) + rb;
  }
  // CommonPairTable's entry in its directory.
  std::size_t PairId(int tlevel, int itheta0, int ra, int rb) const {
    return pair_offset_[tlevel] +
           (static_cast<std::size_t>(itheta0) >> tlevel) * pair_tables_per_block_ +
           PairIndex(ra, rb);
  }
  // The entry's table, or an empty one while it is not made.
  CellTable Made(const TableRef& ref) const {
    const std::uint64_t entry = ref.load(std::memory_order_acquire);
    const auto* words = reinterpret_cast<const std::uint64_t*>(entry & kAddressMask);
    return {words, static_cast<int>(entry >> kRunShift), static_cast<int>(entry & 63) * 8,
            mask_bytes_};
  }
  // Where residue (ra, rb) of blocks of 2 steps lies in a block's CommonPairGroups.
  std::size_t PairIndex(int ra, int rb) const {
    const int half = std::max(1, (1 << shift_) / 2);
    return static_cast<std::size_t>(ra / 2) * half + rb / 2;
  }
  std::size_t BlockSweptIndexOf(int level, int ra, int rb) const {
    return block_index_[(((static_cast<std::size_t>(level) << shift_) + ra) << shift_) + rb];
  }
  // Enters `g` in `ref` when it fits (every thread that made or found it stores the same value)
  // and returns its CellTable.
  static CellTable Publish(TableRef& ref, const CellGroups& g);
  // Table `index` of the theta block (tlevel >= 1, itheta0), made on first use from its two
  // halves' tables (half_table(itheta0 of the half), of level tlevel - 1): united, or their
  // common bits.
  template <typename Half>
  const CellGroups& BlockTable(int tlevel, int itheta0, size_t index, bool unite,
                               const Half& half_table) const;
};

}  // namespace hpose

#endif  // HPOSE_CORE_SCORING_POSE_LATTICE_H_
