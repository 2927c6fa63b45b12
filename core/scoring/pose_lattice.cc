#include "core/scoring/pose_lattice.h"

#include <algorithm>
#include <cassert>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <utility>

#include "core/scoring/column_occupancy.h"

namespace hpose {

Status PoseLattice::Validate() const {
  if (!(resolution_m >= 0.001 && resolution_m <= 0.5)) {
    return MakeError(
        ErrorCode::kInvalidArgument,
        "lattice resolution " + std::to_string(resolution_m) + " m is outside [0.001, 0.5] m");
  }
  if (subdivisions < 1 || subdivisions > 64) {
    return MakeError(
        ErrorCode::kInvalidArgument,
        "lattice subdivisions " + std::to_string(subdivisions) + " is outside [1, 64]");
  }
  if (angle_steps < 4 || angle_steps > 36000) {
    return MakeError(
        ErrorCode::kInvalidArgument,
        "lattice angle_steps " + std::to_string(angle_steps) + " is outside [4, 36000]");
  }
  return Status::Ok();
}

int WrapAngleIndex(const PoseLattice& lattice, int itheta) {
  const int n = lattice.angle_steps;
  const int r = itheta % n;
  return r < 0 ? r + n : r;
}

Pose2D ToPose(const PoseLattice& lattice, const LatticePose& p) {
  return Pose2D{p.ix * lattice.step_m(), p.iy * lattice.step_m(),
                NormalizeAngle(WrapAngleIndex(lattice, p.itheta) * lattice.angle_step_rad())};
}

LatticePose NearestLatticePose(const PoseLattice& lattice, const Pose2D& pose) {
  LatticePose p;
  p.ix = static_cast<int>(std::lround(pose.x / lattice.step_m()));
  p.iy = static_cast<int>(std::lround(pose.y / lattice.step_m()));
  p.itheta =
      WrapAngleIndex(lattice, static_cast<int>(std::lround(pose.theta / lattice.angle_step_rad())));
  return p;
}

Eigen::Vector3i CellOf(const Eigen::Vector3f& p, double resolution_m) {
  const double f = 1.0 / resolution_m;  // as OctoMap's resolution_factor.
  return Eigen::Vector3i(static_cast<int>(std::floor(f * static_cast<double>(p.x()))),
                         static_cast<int>(std::floor(f * static_cast<double>(p.y()))),
                         static_cast<int>(std::floor(f * static_cast<double>(p.z()))));
}

RotatedTemplate RotateTemplate(const VoxelTemplate& tpl, const PoseLattice& lattice, int itheta) {
  return RotatePoints(tpl.VoxelSurfaceCentroids(), lattice, itheta);
}

RotatedTemplate RotatePoints(const std::vector<Eigen::Vector3f>& points, const PoseLattice& lattice,
                             int itheta) {
  RotatedTemplate r;
  r.itheta = WrapAngleIndex(lattice, itheta);
  const double theta = r.itheta * lattice.angle_step_rad();
  const double c = std::cos(theta);
  const double s = std::sin(theta);
  const double q_factor = lattice.subdivisions / lattice.resolution_m;
  const double z_factor = 1.0 / lattice.resolution_m;
  r.sub_cells.reserve(points.size());
  r.q_min = Eigen::Vector2i(INT_MAX, INT_MAX);
  r.q_max = Eigen::Vector2i(INT_MIN, INT_MIN);
  for (const Eigen::Vector3f& v : points) {
    const double px = v.x();
    const double py = v.y();
    const int qx = static_cast<int>(std::floor((c * px - s * py) * q_factor));
    const int qy = static_cast<int>(std::floor((s * px + c * py) * q_factor));
    const int cz = static_cast<int>(std::floor(z_factor * static_cast<double>(v.z())));
    r.sub_cells.emplace_back(qx, qy, cz);
    r.q_min = r.q_min.cwiseMin(Eigen::Vector2i(qx, qy));
    r.q_max = r.q_max.cwiseMax(Eigen::Vector2i(qx, qy));
  }
  if (r.sub_cells.empty()) {
    r.q_min.setZero();
    r.q_max.setZero();
    return r;
  }
  int z_lo = INT_MAX, z_hi = INT_MIN;
  for (const Eigen::Vector3i& q : r.sub_cells) {
    z_lo = std::min(z_lo, q.z());
    z_hi = std::max(z_hi, q.z());
  }
  r.z_base = z_lo;
  r.z_words = (z_hi - z_lo) / 64 + 1;
  std::vector<Eigen::Vector3i> sorted = r.sub_cells;
  std::sort(sorted.begin(), sorted.end(), [](const Eigen::Vector3i& a, const Eigen::Vector3i& b) {
    return a.x() != b.x() ? a.x() < b.x() : (a.y() != b.y() ? a.y() < b.y() : a.z() < b.z());
  });
  for (const Eigen::Vector3i& q : sorted) {
    if (r.column_q.empty() || r.column_q.back() != q.head<2>()) {
      r.column_q.push_back(q.head<2>());
      r.column_masks.resize(r.column_masks.size() + r.z_words, 0);
    }
    const int bit = q.z() - r.z_base;
    r.column_masks[(r.column_q.size() - 1) * r.z_words + bit / 64] |= std::uint64_t{1}
                                                                      << (bit % 64);
  }
  return r;
}

namespace {

// A template's points grouped by equal (x, y): every rotation moves them together, so the
// rotations and the theta blocks are computed per column (a few hundred) instead of per point
// (a few thousand), with no per-rotation sort of the points.
struct PointColumns {
  std::vector<Eigen::Vector2f> xy;  // per column.
  std::vector<int> point_column;    // per point.
  std::vector<int> point_z;         // per point: z cell.
  int z_base = 0;
  int z_words = 0;
  std::vector<std::uint64_t> masks;  // z_words per column.
};

PointColumns GroupPoints(const std::vector<Eigen::Vector3f>& points, double resolution_m) {
  PointColumns g;
  const double z_factor = 1.0 / resolution_m;
  std::map<std::pair<float, float>, int> index;
  int z_lo = INT_MAX, z_hi = INT_MIN;
  for (const Eigen::Vector3f& v : points) {
    const auto [it, added] = index.try_emplace({v.x(), v.y()}, static_cast<int>(g.xy.size()));
    if (added) g.xy.emplace_back(v.x(), v.y());
    g.point_column.push_back(it->second);
    const int z = static_cast<int>(std::floor(z_factor * static_cast<double>(v.z())));
    g.point_z.push_back(z);
    z_lo = std::min(z_lo, z);
    z_hi = std::max(z_hi, z);
  }
  if (points.empty()) return g;
  g.z_base = z_lo;
  g.z_words = (z_hi - z_lo) / 64 + 1;
  g.masks.assign(g.xy.size() * g.z_words, 0);
  for (size_t i = 0; i < points.size(); ++i) {
    const int bit = g.point_z[i] - g.z_base;
    g.masks[static_cast<size_t>(g.point_column[i]) * g.z_words + bit / 64] |= std::uint64_t{1}
                                                                              << (bit % 64);
  }
  return g;
}

// Sub-voxel (qx, qy) of every column at lattice angle itheta, exactly as RotatePoints computes
// them for each point.
std::vector<Eigen::Vector2i> RotateColumnsQ(const PointColumns& g, const PoseLattice& lattice,
                                            int itheta) {
  const double theta = itheta * lattice.angle_step_rad();
  const double c = std::cos(theta);
  const double s = std::sin(theta);
  const double q_factor = lattice.subdivisions / lattice.resolution_m;
  std::vector<Eigen::Vector2i> q;
  q.reserve(g.xy.size());
  for (const Eigen::Vector2f& v : g.xy) {
    const double px = v.x();
    const double py = v.y();
    q.emplace_back(static_cast<int>(std::floor((c * px - s * py) * q_factor)),
                   static_cast<int>(std::floor((s * px + c * py) * q_factor)));
  }
  return q;
}

// The column view of a set of template columns placed at `corner` with `extent` each (0 for a
// single rotation): columns with equal (corner, extent) merged, sorted by corner then extent.
void FillColumns(const PointColumns& g, const std::vector<Eigen::Vector2i>& corner,
                 const std::vector<int>* extent, RotatedTemplate* r) {
  std::vector<int> order(corner.size());
  for (size_t k = 0; k < order.size(); ++k) order[k] = static_cast<int>(k);
  const auto ext = [&](int k) { return extent != nullptr ? (*extent)[k] : 0; };
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    if (corner[a].x() != corner[b].x()) return corner[a].x() < corner[b].x();
    if (corner[a].y() != corner[b].y()) return corner[a].y() < corner[b].y();
    return ext(a) < ext(b);
  });
  r->z_base = g.z_base;
  r->z_words = g.z_words;
  r->column_q.reserve(order.size());
  r->column_masks.reserve(order.size() * g.z_words);
  if (extent != nullptr) r->column_extent.reserve(order.size());
  for (int k : order) {
    const bool same = !r->column_q.empty() && r->column_q.back() == corner[k] &&
                      (extent == nullptr || r->column_extent.back() == ext(k));
    if (!same) {
      r->column_q.push_back(corner[k]);
      if (extent != nullptr) r->column_extent.push_back(ext(k));
      r->column_masks.resize(r->column_masks.size() + g.z_words, 0);
    }
    std::uint64_t* m = &r->column_masks[(r->column_q.size() - 1) * g.z_words];
    for (int w = 0; w < g.z_words; ++w) m[w] |= g.masks[static_cast<size_t>(k) * g.z_words + w];
  }
}

// RotatePoints for grouped points whose columns rotation itheta places at q (RotateColumnsQ):
// the same RotatedTemplate without its sub_cells (the column view holds the same cells, and
// 360 rotations of a few thousand sub-cells are megabytes that a process first touching them
// pays for page by page).
RotatedTemplate RotateColumns(const PointColumns& g, const std::vector<Eigen::Vector2i>& q,
                              int itheta) {
  RotatedTemplate r;
  r.itheta = itheta;
  if (g.point_column.empty()) return r;
  r.q_min = q.front();
  r.q_max = q.front();
  for (const Eigen::Vector2i& p : q) {
    r.q_min = r.q_min.cwiseMin(p);
    r.q_max = r.q_max.cwiseMax(p);
  }
  FillColumns(g, q, nullptr, &r);
  return r;
}

// Fills column_cxe / column_cy for a power-of-two subdivision (2^shift).
void AddCellTables(int shift, RotatedTemplate* r) {
  if (shift < 0) return;
  const int mask = (1 << shift) - 1;
  r->column_cxe.clear();
  r->column_cy.clear();
  r->column_cxe.reserve(r->column_q.size());
  r->column_cy.reserve(r->column_q.size());
  for (const Eigen::Vector2i& q : r->column_q) {
    const int e = 2 * ((q.x() & mask) != 0 ? 1 : 0) + ((q.y() & mask) != 0 ? 1 : 0);
    r->column_cxe.push_back(4 * (q.x() >> shift) + e);
    r->column_cy.push_back(q.y() >> shift);
  }
}

// Residues per axis of blocks of 2^level steps: their first steps are the multiples of
// min(2^level, s) below s.
int SweptResidues(int level, int s) { return std::max(1, s >> level); }

// Where SweptGroups(level, ra, rb) lies in a rotation's list of tables.
size_t SweptIndex(int level, int ra, int rb, int s) {
  size_t index = 0;
  for (int lv = 1; lv < level; ++lv) {
    const int n = SweptResidues(lv, s);
    index += static_cast<size_t>(n) * n;
  }
  const int step = std::min(1 << level, s);
  return index + static_cast<size_t>(ra / step) * SweptResidues(level, s) + rb / step;
}

// SweptIndex with the S^2 residues of level 0 (single translations: Groups) first.
size_t BlockSweptIndex(int level, int ra, int rb, int s) {
  if (level == 0) return static_cast<size_t>(ra) * s + rb;
  return static_cast<size_t>(s) * s + SweptIndex(level, ra, rb, s);
}

// The farthest sub-voxel step from the origin, on either axis, that a column of r covers.
int ColumnReach(const RotatedTemplate& r) {
  int reach = 0;
  for (size_t c = 0; c < r.column_q.size(); ++c) {
    const Eigen::Vector2i& q = r.column_q[c];
    const int e = r.column_extent.empty() ? 0 : r.column_extent[c];
    reach = std::max({reach, std::abs(q.x()), std::abs(q.y()), std::abs(q.x() + e) + 1,
                      std::abs(q.y() + e) + 1});
  }
  return reach;
}

}  // namespace

TemplateRotations::TemplateRotations(const VoxelTemplate& tpl, const PoseLattice& lattice)
    : TemplateRotations(tpl.name, tpl.Height(), tpl.VoxelSurfaceCentroids(), lattice) {}

TemplateRotations::TemplateRotations(std::string name, double height_m,
                                     const std::vector<Eigen::Vector3f>& points,
                                     const PoseLattice& lattice)
    : name_(std::move(name)), height_m_(height_m), voxels_(points.size()), lattice_(lattice) {
  const PointColumns g = GroupPoints(points, lattice.resolution_m);
  rotations_.reserve(lattice.angle_steps);
  blocks_.resize(kThetaLevels - 1);
  level_extent_.assign(kThetaLevels - 1, 0);
  // The rotations a block of the top theta level spans, a group at a time: every block lies
  // within one group, and what a group needs (its rotations' and blocks' sweeps) is kept only
  // while it is built, in the same few hundred kilobytes for every group.
  const int group = 1 << (kThetaLevels - 1);
  // Per column and block of the level being built, the square its sub-voxel coordinates
  // sweep: [lo, hi].
  std::vector<std::vector<Eigen::Vector2i>> lo, hi, next_lo, next_hi;
  std::vector<int> extent(g.xy.size());
  for (int first = 0; first < lattice.angle_steps; first += group) {
    const int n = std::min(group, lattice.angle_steps - first);
    lo.resize(n);
    for (int i = 0; i < n; ++i) {
      lo[i] = RotateColumnsQ(g, lattice, first + i);
      rotations_.push_back(RotateColumns(g, lo[i], first + i));
    }
    hi = lo;
    for (int level = 1; level < kThetaLevels; ++level) {
      next_lo.resize((lo.size() + 1) / 2);
      next_hi.resize(next_lo.size());
      for (size_t k = 0; k < lo.size(); k += 2) {
        std::vector<Eigen::Vector2i>& block_lo = next_lo[k / 2];
        std::vector<Eigen::Vector2i>& block_hi = next_hi[k / 2];
        block_lo = lo[k];
        block_hi = hi[k];
        if (k + 1 < lo.size()) {
          for (size_t c = 0; c < g.xy.size(); ++c) {
            block_lo[c] = block_lo[c].cwiseMin(lo[k + 1][c]);
            block_hi[c] = block_hi[c].cwiseMax(hi[k + 1][c]);
          }
        }
        for (size_t c = 0; c < g.xy.size(); ++c) {
          extent[c] = (block_hi[c] - block_lo[c]).maxCoeff();
          level_extent_[level - 1] = std::max(level_extent_[level - 1], extent[c]);
          max_block_extent_ = std::max(max_block_extent_, extent[c]);
        }
        RotatedTemplate block;
        block.itheta = ((first >> level) + static_cast<int>(k / 2)) << level;
        if (!g.xy.empty()) FillColumns(g, block_lo, &extent, &block);
        blocks_[level - 1].push_back(std::move(block));
      }
      std::swap(lo, next_lo);
      std::swap(hi, next_hi);
    }
  }
  z_words_ = g.z_words;
  const double q_to_m = lattice.resolution_m / lattice.subdivisions;
  for (const Eigen::Vector2i& q : rotations_.front().column_q) {
    rim_radius_m_ =
        std::max(rim_radius_m_, std::hypot((q.x() + 1.0) * q_to_m, (q.y() + 1.0) * q_to_m));
    rim_radius_m_ = std::max(rim_radius_m_, std::hypot(q.x() * q_to_m, q.y() * q_to_m));
  }
  PrepareTables();
  if (z_words_ > 1 && shift_ >= 0) {
    for (int word = 0; word < z_words_; ++word) {
      // The slab's lowest z cell: the lowest bit any column sets in this word.
      std::uint64_t any = 0;
      const RotatedTemplate& first = rotations_.front();
      for (size_t c = 0; c < first.column_q.size(); ++c) {
        any |= first.column_masks[c * z_words_ + word];
      }
      if (any == 0) continue;  // a gap of 64 cells or more.
      slabs_.push_back(std::unique_ptr<TemplateRotations>(
          new TemplateRotations(*this, word, __builtin_ctzll(any))));
    }
  }
}

TemplateRotations::TemplateRotations(const TemplateRotations& parent, int word, int offset)
    : name_(parent.name_), height_m_(parent.height_m_), lattice_(parent.lattice_) {
  const int words = parent.z_words_;
  // The columns of `from` with a bit in the word, their masks shifted to the slab's base. The
  // parent's columns are sorted and each (corner, extent) once, so the kept ones are too: the
  // columns a rotation of the slab's own points would make. With `disjoint`, a rotation's
  // free-space masks (CellDisjointMasks treats each word on its own, and a column without a bit
  // in the word takes none from the others) are cut alike into `disjoint_out`.
  const auto cut = [&](const RotatedTemplate& from, const std::vector<std::uint64_t>* disjoint,
                       std::vector<std::uint64_t>* disjoint_out) {
    RotatedTemplate r;
    r.itheta = from.itheta;
    r.z_base = from.z_base + 64 * word + offset;
    r.z_words = 1;
    for (size_t c = 0; c < from.column_q.size(); ++c) {
      const std::uint64_t mask = from.column_masks[c * words + word] >> offset;
      if (mask == 0) continue;
      r.column_q.push_back(from.column_q[c]);
      r.column_masks.push_back(mask);
      if (!from.column_extent.empty()) r.column_extent.push_back(from.column_extent[c]);
      if (disjoint != nullptr) disjoint_out->push_back((*disjoint)[c * words + word] >> offset);
    }
    return r;
  };
  rotations_.reserve(parent.rotations_.size());
  disjoint_.resize(parent.rotations_.size());
  for (size_t i = 0; i < parent.rotations_.size(); ++i) {
    RotatedTemplate r = cut(parent.rotations_[i], &parent.disjoint_[i], &disjoint_[i]);
    if (!r.column_q.empty()) {
      r.q_min = r.column_q.front();
      r.q_max = r.column_q.front();
      for (const Eigen::Vector2i& q : r.column_q) {
        r.q_min = r.q_min.cwiseMin(q);
        r.q_max = r.q_max.cwiseMax(q);
      }
    }
    rotations_.push_back(std::move(r));
  }
  level_extent_.assign(parent.level_extent_.size(), 0);
  for (size_t level = 0; level < parent.blocks_.size(); ++level) {
    std::vector<RotatedTemplate> blocks;
    blocks.reserve(parent.blocks_[level].size());
    for (const RotatedTemplate& from : parent.blocks_[level]) {
      blocks.push_back(cut(from, nullptr, nullptr));
      for (int extent : blocks.back().column_extent) {
        level_extent_[level] = std::max(level_extent_[level], extent);
        max_block_extent_ = std::max(max_block_extent_, extent);
      }
    }
    blocks_.push_back(std::move(blocks));
  }
  z_words_ = 1;
  PrepareTables();
}

void TemplateRotations::PrepareTables() {
  int shift = -1;
  for (int k = 0; k < 31; ++k) {
    if ((1 << k) == lattice_.subdivisions) shift = k;
  }
  if (shift >= 0) {
    // The cell tables' runs take cx in [kRunMinX, kRunMaxX] (gather_sums.h) and hold cells
    // within a translation block's reach of the template's origin. A template reaching farther
    // (thousands of cells: metres on a lattice of millimetre voxels) goes without them, by the
    // columns' path.
    int reach = 0;
    for (const RotatedTemplate& r : rotations_) reach = std::max(reach, ColumnReach(r));
    for (const std::vector<RotatedTemplate>& level : blocks_) {
      for (const RotatedTemplate& r : level) reach = std::max(reach, ColumnReach(r));
    }
    if (((reach + (1 << kSweptLevels)) >> shift) + 2 > kRunMaxX) shift = -1;
  }
  shift_ = shift;
  groups_.resize(rotations_.size());
  pair_tables_.resize(rotations_.size());
  groups_once_ = std::make_unique<std::once_flag[]>(rotations_.size());
  swept_.resize(rotations_.size());
  swept_once_ = std::make_unique<std::once_flag[]>(rotations_.size());
  if (shift >= 0) {
    const int s = 1 << shift;
    // Per theta block: SweptBlockGroups' levels and residues, then CommonBlockGroups'.
    block_tables_ = BlockSweptIndex(kSweptLevels + 1, 0, 0, s) + static_cast<size_t>(s) * s;
    for (int t = 1; t < kThetaLevels; ++t) {
      const size_t tables = ((rotations_.size() + (size_t{1} << t) - 1) >> t) * block_tables_;
      swept_blocks_.emplace_back(tables);
      swept_blocks_once_.push_back(std::make_unique<std::once_flag[]>(tables));
    }
    pair_tables_per_block_ = static_cast<size_t>(SweptResidues(1, s)) * SweptResidues(1, s);
    size_t pair_entries = 0;
    for (int t = 0; t < kThetaLevels; ++t) {
      const size_t blocks = (rotations_.size() + (size_t{1} << t) - 1) >> t;
      common_pairs_.emplace_back(blocks);
      common_pairs_once_.push_back(std::make_unique<std::once_flag[]>(blocks));
      pair_offset_[t] = pair_entries;
      pair_entries += blocks * pair_tables_per_block_;
    }
    pair_refs_ = std::make_unique<TableRef[]>(pair_entries);
    // The directory: level 0's rotations, then each theta level's blocks.
    size_t entries = 0;
    for (int t = 0; t < kThetaLevels; ++t) {
      table_offset_[t] = entries;
      entries += ((rotations_.size() + (size_t{1} << t) - 1) >> t) * block_tables_;
    }
    table_refs_ = std::make_unique<TableRef[]>(entries);
    block_index_.assign(static_cast<size_t>(kSweptLevels + 1) * s * s, 0);
    for (int level = 0; level <= kSweptLevels; ++level) {
      // Level l's residues are the multiples of min(2^l, S); the others are never asked for.
      const int step = level == 0 ? 1 : std::min(1 << level, s);
      for (int ra = 0; ra < s; ra += step) {
        for (int rb = 0; rb < s; rb += step) {
          block_index_[(static_cast<size_t>(level) * s + ra) * s + rb] =
              static_cast<std::uint16_t>(BlockSweptIndex(level, ra, rb, s));
        }
      }
    }
  }
  bool first = true;
  const auto visit = [&](RotatedTemplate* r) {
    AddCellTables(shift, r);
    for (const Eigen::Vector2i& q : r->column_q) {
      column_q_min_ = first ? q : column_q_min_.cwiseMin(q);
      column_q_max_ = first ? q : column_q_max_.cwiseMax(q);
      first = false;
    }
  };
  const bool with_disjoint = disjoint_.empty();  // a slab's come from its parent's.
  for (RotatedTemplate& r : rotations_) {
    visit(&r);
    if (with_disjoint) disjoint_.push_back(CellDisjointMasks(r, lattice_.subdivisions));
  }
  for (std::vector<RotatedTemplate>& level : blocks_) {
    for (RotatedTemplate& r : level) visit(&r);
  }
  // The cell tables' masks (one-word columns only) hold the bits any column sets: every table
  // unites or intersects rotations' masks.
  std::uint64_t any = 0;
  if (z_words_ == 1) {
    for (const RotatedTemplate& r : rotations_) {
      for (const std::uint64_t m : r.column_masks) any |= m;
    }
  }
  mask_bytes_ = MaskBytes(any);
}

namespace {

// Lays out a CellGroups from its cells, given row by row (cy, then cx, ascending), each once: a
// cell right after the previous one in its row extends its run. Cell coordinates must fit a run
// header (kRunMinX to kRunMaxX; PrepareTables sees to it). Kept for table after table,
// it allocates once per table (the table's exact size).
class CellGroupsBuilder {
 public:
  void Append(int cx, int cy, std::uint64_t mask) {
    assert(cx >= kRunMinX && cx <= kRunMaxX && cy > -kRunRowBias && cy < kRunRowBias - 1);
    masks_.push_back(mask);
    if (!runs_.empty()) {
      CellRun& r = runs_.back();
      if (r.cy == cy && r.cx + r.len == cx && r.len < CellGroups::kMaxRun) {
        ++r.len;
        return;
      }
    }
    runs_.push_back({cx, cy, 1});
  }
  // The table of the cells appended since the last Take(), in `arena`, its masks mask_bytes
  // bytes each (every mask must fit).
  CellGroups Take(TableArena* arena, int mask_bytes) {
    CellGroups g;
    g.words = TableWords(TableAllocator<std::uint64_t>(arena));
    g.runs = static_cast<int>(runs_.size());
    g.cell_count = static_cast<int>(masks_.size());
    g.mask_bytes = mask_bytes;
    g.words.resize(RunTableWords(g.runs, g.cell_count, mask_bytes));
    WriteRunTable(runs_.data(), g.runs, masks_.data(), g.cell_count, mask_bytes, g.words.data());
    runs_.clear();
    masks_.clear();
    return g;
  }

 private:
  std::vector<CellRun> runs_;
  std::vector<std::uint64_t> masks_;
};

// This thread's builder, for callers that make one table at a time without making another
// meanwhile (no nesting).
CellGroupsBuilder& ThreadBuilder() {
  thread_local CellGroupsBuilder builder;
  return builder;
}

// The cells rotation r's columns reach at the translations of a block of size x size steps
// whose first step has residue (rx, ry) (relative to the block's first cell): per cell the union
// of the masks of every column landing in it at some translation of the block, row by row. Size
// 1 is a single translation (Groups).
CellGroups ReachedCells(const RotatedTemplate& r, int rx, int ry, int size, int shift,
                        int mask_bytes, TableArena* arena) {
  thread_local std::vector<std::uint64_t> grid;  // all zero between calls.
  const int x_lo = (r.q_min.x() + rx) >> shift, y_lo = (r.q_min.y() + ry) >> shift;
  const int nx = ((r.q_max.x() + rx + size - 1) >> shift) - x_lo + 1;
  const int ny = ((r.q_max.y() + ry + size - 1) >> shift) - y_lo + 1;
  if (grid.size() < static_cast<size_t>(nx) * ny) grid.resize(static_cast<size_t>(nx) * ny, 0);
  std::uint64_t* cells = grid.data();
  for (size_t c = 0; c < r.column_q.size(); ++c) {
    const int qx = r.column_q[c].x() + rx, qy = r.column_q[c].y() + ry;
    for (int y = (qy >> shift) - y_lo; y <= ((qy + size - 1) >> shift) - y_lo; ++y) {
      for (int x = (qx >> shift) - x_lo; x <= ((qx + size - 1) >> shift) - x_lo; ++x) {
        cells[static_cast<size_t>(y) * nx + x] |= r.column_masks[c];
      }
    }
  }
  for (int y = 0; y < ny; ++y) {  // rows in the order of the occupancy's layout.
    for (int x = 0; x < nx; ++x) {
      std::uint64_t& cell = cells[static_cast<size_t>(y) * nx + x];
      const std::uint64_t m = cell;
      cell = 0;
      if (m == 0) continue;
      ThreadBuilder().Append(x + x_lo, y + y_lo, m);
    }
  }
  return ThreadBuilder().Take(arena, mask_bytes);
}

// The cells r's columns cover at every translation of a block of `size` steps per side from
// residue (rx, ry), relative to the block's first cell as ReachedCells's, each with the bits
// set there at all of them (cells left with none are left out).
CellGroups CommonCells(const RotatedTemplate& r, int rx, int ry, int size, int shift,
                       int mask_bytes, TableArena* arena) {
  thread_local std::vector<std::uint64_t> common, placed;
  const int x_lo = (r.q_min.x() + rx) >> shift, y_lo = (r.q_min.y() + ry) >> shift;
  const int nx = ((r.q_max.x() + rx + size - 1) >> shift) - x_lo + 1;
  const int ny = ((r.q_max.y() + ry + size - 1) >> shift) - y_lo + 1;
  const size_t cells = static_cast<size_t>(nx) * ny;
  common.assign(cells, ~std::uint64_t{0});
  placed.resize(cells);
  for (int i = 0; i < size; ++i) {
    for (int j = 0; j < size; ++j) {
      std::fill(placed.begin(), placed.begin() + static_cast<std::ptrdiff_t>(cells), 0);
      for (size_t c = 0; c < r.column_q.size(); ++c) {
        const int x = ((r.column_q[c].x() + rx + i) >> shift) - x_lo;
        const int y = ((r.column_q[c].y() + ry + j) >> shift) - y_lo;
        placed[static_cast<size_t>(y) * nx + x] |= r.column_masks[c];
      }
      for (size_t k = 0; k < cells; ++k) common[k] &= placed[k];
    }
  }
  for (int y = 0; y < ny; ++y) {  // rows in the order of the occupancy's layout.
    for (int x = 0; x < nx; ++x) {
      const std::uint64_t m = common[static_cast<size_t>(y) * nx + x];
      if (m != 0) ThreadBuilder().Append(x + x_lo, y + y_lo, m);
    }
  }
  return ThreadBuilder().Take(arena, mask_bytes);
}

}  // namespace

const CellGroups& TemplateRotations::Groups(int itheta, int rx, int ry) const {
  const int s = 1 << shift_;
  std::call_once(groups_once_[itheta], [&] {
    const RotatedTemplate& r = rotations_[itheta];
    std::vector<CellGroups>& out = groups_[itheta];
    out.reserve(static_cast<size_t>(s) * s);
    // One cell per column's cell, its columns' masks united.
    for (int x = 0; x < s; ++x) {
      for (int y = 0; y < s; ++y)
        out.push_back(ReachedCells(r, x, y, 1, shift_, mask_bytes_, arena_.get()));
    }
    // Blocks of two steps at even residues: the window starts at the cell of q + residue and
    // is two cells long where q + residue is the last step of its cell.
    const int half = s / 2;
    std::vector<PairBlockTable>& pairs = pair_tables_[itheta];
    pairs.resize(static_cast<size_t>(half) * half);
    for (int x = 0; x < half; ++x) {
      for (int y = 0; y < half; ++y) {
        PairBlockTable& t = pairs[static_cast<size_t>(x) * half + y];
        t.cxe.reserve(r.column_q.size());
        t.cy.reserve(r.column_q.size());
        for (const Eigen::Vector2i& q : r.column_q) {
          const int qx = q.x() + 2 * x, qy = q.y() + 2 * y;
          const int ex = (qx & (s - 1)) == s - 1 ? 1 : 0;
          const int ey = (qy & (s - 1)) == s - 1 ? 1 : 0;
          t.cxe.push_back(4 * (qx >> shift_) + 2 * ex + ey);
          t.cy.push_back(qy >> shift_);
        }
      }
    }
  });
  return groups_[itheta][static_cast<size_t>(rx) * s + ry];
}

const PairBlockTable& TemplateRotations::PairTable(int itheta, int ra, int rb) const {
  Groups(itheta, 0, 0);  // makes both on first use.
  const int half = (1 << shift_) / 2;
  return pair_tables_[itheta][static_cast<size_t>(ra / 2) * half + rb / 2];
}

namespace {

// Walks a CellGroups' cells in order (row by row), each with a key that orders them so.
class CellCursor {
 public:
  static constexpr std::int64_t kDone = INT64_MAX;  // the key once past the last cell.

  explicit CellCursor(const CellGroups& g) : g_(g) { Load(); }
  std::int64_t key() const { return key_; }
  int cx() const { return cx_ + i_; }
  int cy() const { return cy_; }
  std::uint64_t mask() const { return g_.mask(k_); }
  void Next() {
    ++k_;
    ++key_;
    if (++i_ < len_) return;
    ++r_;
    i_ = 0;
    Load();
  }

 private:
  void Load() {
    if (r_ >= g_.runs) {
      key_ = kDone;
      return;
    }
    const RunHeaderWord h = RunHeaderAt(g_.words.data(), r_);
    cx_ = RunHeaderX(h);
    cy_ = RunHeaderY(h);
    len_ = RunHeaderLength(h);
    // cx, cy fit 16 bits; multiplied, not shifted: cy may be negative.
    key_ = static_cast<std::int64_t>(cy_) * (std::int64_t{1} << 32) + cx_;
  }

  const CellGroups& g_;
  int k_ = 0;  // the current cell's index (its mask's).
  int r_ = 0, i_ = 0;
  int cx_ = 0, cy_ = 0, len_ = 0;
  std::int64_t key_ = kDone;
};

// Merges the cells of a and b (each listed row by row, once). unite: every cell of either, the
// masks of a cell in both united; else the cells of both, with the bits both set (cells with
// none left out).
CellGroups MergeCellGroups(const CellGroups& a, const CellGroups& b, bool unite,
                           TableArena* arena) {
  assert(a.mask_bytes == b.mask_bytes);
  CellGroupsBuilder* out = &ThreadBuilder();
  CellCursor ca(a), cb(b);
  while (ca.key() != CellCursor::kDone || cb.key() != CellCursor::kDone) {
    const bool take_a = ca.key() <= cb.key(), take_b = cb.key() <= ca.key();
    const int cx = take_a ? ca.cx() : cb.cx(), cy = take_a ? ca.cy() : cb.cy();
    const std::uint64_t mask_a = take_a ? ca.mask() : 0, mask_b = take_b ? cb.mask() : 0;
    if (take_a) ca.Next();
    if (take_b) cb.Next();
    if (unite) {
      out->Append(cx, cy, mask_a | mask_b);
    } else if ((mask_a & mask_b) != 0) {
      out->Append(cx, cy, mask_a & mask_b);
    }
  }
  return out->Take(arena, a.mask_bytes);
}

}  // namespace

template <typename Half>
const CellGroups& TemplateRotations::BlockTable(int tlevel, int itheta0, size_t index, bool unite,
                                                const Half& half_table) const {
  assert(tlevel >= 1 && tlevel < kThetaLevels && (itheta0 & ((1 << tlevel) - 1)) == 0);
  const size_t slot = (static_cast<size_t>(itheta0) >> tlevel) * block_tables_ + index;
  std::call_once(swept_blocks_once_[tlevel - 1][slot], [&] {
    // Both halves first (made on first use too), then the merge.
    const int half = 1 << (tlevel - 1);
    const CellGroups& first = half_table(itheta0);
    CellGroups& out = swept_blocks_[tlevel - 1][slot];
    if (itheta0 + half >= static_cast<int>(rotations_.size())) {  // the last block: one half.
      out = first;
      return;
    }
    const CellGroups& second = half_table(itheta0 + half);
    out = MergeCellGroups(first, second, unite, arena_.get());
  });
  return swept_blocks_[tlevel - 1][slot];
}

const CellGroups& TemplateRotations::CommonBlockGroups(int tlevel, int itheta0, int ra,
                                                       int rb) const {
  if (tlevel == 0) return Groups(itheta0, ra, rb);
  const int s = 1 << shift_;
  const size_t index =
      block_tables_ - static_cast<size_t>(s) * s + static_cast<size_t>(ra) * s + rb;
  return BlockTable(tlevel, itheta0, index, /*unite=*/false, [&](int itheta) -> const CellGroups& {
    return CommonBlockGroups(tlevel - 1, itheta, ra, rb);
  });
}

const CellGroups& TemplateRotations::SweptBlockGroups(int tlevel, int itheta0, int level, int ra,
                                                      int rb) const {
  if (tlevel == 0)
    return level == 0 ? Groups(itheta0, ra, rb) : SweptGroups(itheta0, level, ra, rb);
  const int s = 1 << shift_;
  return BlockTable(tlevel, itheta0, BlockSweptIndex(level, ra, rb, s), /*unite=*/true,
                    [&](int itheta) -> const CellGroups& {
                      return SweptBlockGroups(tlevel - 1, itheta, level, ra, rb);
                    });
}

void TemplateRotations::MakeTables(int max_tlevel, int begin, int end) const {
  for (const std::unique_ptr<TemplateRotations>& slab : slabs_) {
    slab->MakeTables(max_tlevel, begin, end);
  }
  if (!has_cell_groups()) return;
  const int steps = static_cast<int>(rotations_.size());
  const int s = 1 << shift_;
  max_tlevel = std::min(max_tlevel, kThetaLevels - 1);
  // Each table is made and entered in the directory (SweptTable and the others), so that the
  // searches find every one there, also when they only prefetch it (the *IfMade getters).
  const int pair_step = std::min(2, s);
  const auto make_block = [&](int t, int first) {
    for (int lv = 0; lv <= kSweptLevels; ++lv) {
      const int step = std::min(1 << lv, s);
      for (int ra = 0; ra < s; ra += step) {
        for (int rb = 0; rb < s; rb += step) SweptTable(t, first, lv, ra, rb);
      }
    }
    for (int ra = 0; ra < s; ra += pair_step) {
      for (int rb = 0; rb < s; rb += pair_step) CommonPairTable(t, first, ra, rb);
    }
  };
  for (int i = std::max(0, begin); i < std::min(end, steps); ++i) {
    make_block(0, i);  // Groups and SweptGroups.
    // Theta blocks whose last rotation is i: their halves are made by then.
    for (int t = 1; t <= max_tlevel; ++t) {
      const int first = i & ~((1 << t) - 1);
      if (i != std::min(steps, first + (1 << t)) - 1) continue;
      make_block(t, first);
      for (int ra = 0; ra < s; ++ra) {
        for (int rb = 0; rb < s; ++rb) CommonTable(t, first, ra, rb);
      }
    }
  }
}

const CellGroups& TemplateRotations::CommonPairGroups(int tlevel, int itheta0, int ra,
                                                      int rb) const {
  assert(has_cell_groups() && tlevel >= 0 && tlevel < kThetaLevels &&
         (itheta0 & ((1 << tlevel) - 1)) == 0);
  const int s = 1 << shift_;
  assert(ra >= 0 && rb >= 0 && ra < s && rb < s && (ra | rb) % std::min(2, s) == 0);
  const size_t block = static_cast<size_t>(itheta0) >> tlevel;
  std::call_once(common_pairs_once_[tlevel][block], [&] {
    std::vector<CellGroups>& out = common_pairs_[tlevel][block];
    const int half = tlevel > 0 ? 1 << (tlevel - 1) : 0;
    const int step = std::min(2, s);
    const int residues = SweptResidues(1, s);
    for (int i = 0; i < residues * residues; ++i) {
      const int rx = (i / residues) * step, ry = (i % residues) * step;
      if (tlevel == 0) {
        out.push_back(
            CommonCells(rotations_[itheta0], rx, ry, 2, shift_, mask_bytes_, pair_arena_.get()));
        continue;
      }
      // Both halves' (made on first use too), their common bits; the last block may have one.
      const CellGroups& first = CommonPairGroups(tlevel - 1, itheta0, rx, ry);
      if (itheta0 + half >= static_cast<int>(rotations_.size())) {
        out.push_back(first);
        continue;
      }
      out.push_back(MergeCellGroups(first, CommonPairGroups(tlevel - 1, itheta0 + half, rx, ry),
                                    /*unite=*/false, pair_arena_.get()));
    }
  });
  return common_pairs_[tlevel][block][PairIndex(ra, rb)];
}

const CellGroups& TemplateRotations::SweptGroups(int itheta, int level, int ra, int rb) const {
  assert(has_cell_groups() && level >= 1 && level <= kSweptLevels);
  const int s = 1 << shift_;
  std::call_once(swept_once_[itheta], [&] {
    const RotatedTemplate& r = rotations_[itheta];
    std::vector<CellGroups>& out = swept_[itheta];
    for (int lv = 1; lv <= kSweptLevels; ++lv) {
      const int step = std::min(1 << lv, s);
      const int residues = SweptResidues(lv, s);
      for (int i = 0; i < residues * residues; ++i) {
        const int rx = (i / residues) * step, ry = (i % residues) * step;
        out.push_back(ReachedCells(r, rx, ry, 1 << lv, shift_, mask_bytes_, arena_.get()));
      }
    }
  });
  return swept_[itheta][SweptIndex(level, ra, rb, s)];
}

CellTable TemplateRotations::Publish(TableRef& ref, const CellGroups& g) {
  const auto address = reinterpret_cast<std::uintptr_t>(g.words.data());
  const std::uint64_t lines = CellTable::PrefetchWords(g.words.size()) / 8;
  if ((address & ~kAddressMask) == 0 &&
      static_cast<std::uint64_t>(g.runs) >> (64 - kRunShift) == 0) {
    ref.store(address | lines | static_cast<std::uint64_t>(g.runs) << kRunShift,
              std::memory_order_release);
  }
  return g.table();
}

const RotatedTemplate& TemplateRotations::GetBlock(int level, int itheta0) const {
  if (level == 0) return rotations_[itheta0];
  return blocks_[level - 1][itheta0 >> level];
}

}  // namespace hpose
