#include "core/scoring/pose_lattice.h"

#include <algorithm>
#include <climits>
#include <cmath>

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

// Per template point, the square of sub-voxel coordinates it sweeps over a theta block.
struct Arcs {
  std::vector<Eigen::Vector2i> lo, hi;
};

Arcs ArcsOf(const RotatedTemplate& r) {
  Arcs arcs;
  for (const Eigen::Vector3i& q : r.sub_cells) {
    arcs.lo.push_back(q.head<2>());
    arcs.hi.push_back(q.head<2>());
  }
  return arcs;
}

Arcs Join(const Arcs& a, const Arcs& b) {
  Arcs out = a;
  for (size_t i = 0; i < out.lo.size(); ++i) {
    out.lo[i] = out.lo[i].cwiseMin(b.lo[i]);
    out.hi[i] = out.hi[i].cwiseMax(b.hi[i]);
  }
  return out;
}

// The block's column view: points with equal squares share a column (sorted by corner, then
// side), the side being the larger extent of the two axes.
RotatedTemplate BlockColumns(const Arcs& arcs, const RotatedTemplate& first, int itheta0) {
  struct Entry {
    int qx, qy, extent, z;
  };
  std::vector<Entry> entries;
  entries.reserve(arcs.lo.size());
  for (size_t i = 0; i < arcs.lo.size(); ++i) {
    const Eigen::Vector2i side = arcs.hi[i] - arcs.lo[i];
    entries.push_back({arcs.lo[i].x(), arcs.lo[i].y(), side.maxCoeff(), first.sub_cells[i].z()});
  }
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    if (a.qx != b.qx) return a.qx < b.qx;
    if (a.qy != b.qy) return a.qy < b.qy;
    return a.extent < b.extent;
  });
  RotatedTemplate out;
  out.itheta = itheta0;
  out.z_base = first.z_base;
  out.z_words = first.z_words;
  for (const Entry& e : entries) {
    const Eigen::Vector2i q(e.qx, e.qy);
    if (out.column_q.empty() || out.column_q.back() != q || out.column_extent.back() != e.extent) {
      out.column_q.push_back(q);
      out.column_extent.push_back(e.extent);
      out.column_masks.resize(out.column_masks.size() + out.z_words, 0);
    }
    const int bit = e.z - out.z_base;
    out.column_masks[(out.column_q.size() - 1) * out.z_words + bit / 64] |= std::uint64_t{1}
                                                                            << (bit % 64);
  }
  return out;
}

// Fills column_cxe / column_cy for a power-of-two subdivision (2^shift).
void AddCellTables(int shift, RotatedTemplate* r) {
  if (shift < 0) return;
  const int mask = (1 << shift) - 1;
  r->column_cxe.clear();
  r->column_cy.clear();
  for (const Eigen::Vector2i& q : r->column_q) {
    const int e = 2 * ((q.x() & mask) != 0 ? 1 : 0) + ((q.y() & mask) != 0 ? 1 : 0);
    r->column_cxe.push_back(4 * (q.x() >> shift) + e);
    r->column_cy.push_back(q.y() >> shift);
  }
}

}  // namespace

TemplateRotations::TemplateRotations(const VoxelTemplate& tpl, const PoseLattice& lattice)
    : name_(tpl.name), height_m_(tpl.Height()), lattice_(lattice) {
  rotations_.reserve(lattice.angle_steps);
  const std::vector<Eigen::Vector3f> points = tpl.VoxelSurfaceCentroids();
  for (int i = 0; i < lattice.angle_steps; ++i) {
    rotations_.push_back(RotatePoints(points, lattice, i));
  }
  std::vector<Arcs> arcs;  // of the previous level's blocks.
  for (const RotatedTemplate& r : rotations_) arcs.push_back(ArcsOf(r));
  for (int level = 1; level < kThetaLevels; ++level) {
    std::vector<RotatedTemplate> blocks;
    std::vector<Arcs> joined;
    for (size_t k = 0; k < arcs.size(); k += 2) {
      joined.push_back(k + 1 < arcs.size() ? Join(arcs[k], arcs[k + 1]) : arcs[k]);
      const int start = static_cast<int>(k / 2) << level;
      blocks.push_back(BlockColumns(joined.back(), rotations_[start], start));
      for (int e : blocks.back().column_extent) max_block_extent_ = std::max(max_block_extent_, e);
    }
    blocks_.push_back(std::move(blocks));
    arcs = std::move(joined);
  }
  int shift = -1;
  for (int k = 0; k < 31; ++k) {
    if ((1 << k) == lattice.subdivisions) shift = k;
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
  for (RotatedTemplate& r : rotations_) {
    visit(&r);
    disjoint_.push_back(CellDisjointMasks(r, lattice.subdivisions));
  }
  for (std::vector<RotatedTemplate>& level : blocks_) {
    for (RotatedTemplate& r : level) visit(&r);
  }
}

const RotatedTemplate& TemplateRotations::GetBlock(int level, int itheta0) const {
  if (level == 0) return rotations_[itheta0];
  return blocks_[level - 1][itheta0 >> level];
}

}  // namespace hpose
