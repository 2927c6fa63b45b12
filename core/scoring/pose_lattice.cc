#include "core/scoring/pose_lattice.h"

#include <algorithm>
#include <climits>
#include <cmath>

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

// Union of two column views (both sorted by (qx, qy)): shared columns OR their masks.
RotatedTemplate MergeColumns(const RotatedTemplate& a, const RotatedTemplate& b) {
  RotatedTemplate out;
  out.itheta = a.itheta;
  out.z_base = a.z_base;
  out.z_words = a.z_words;
  const int w = a.z_words;
  auto less = [](const Eigen::Vector2i& p, const Eigen::Vector2i& q) {
    return p.x() != q.x() ? p.x() < q.x() : p.y() < q.y();
  };
  size_t i = 0, j = 0;
  while (i < a.column_q.size() || j < b.column_q.size()) {
    const bool take_a =
        j == b.column_q.size() || (i < a.column_q.size() && !less(b.column_q[j], a.column_q[i]));
    const bool take_b =
        i == a.column_q.size() || (j < b.column_q.size() && !less(a.column_q[i], b.column_q[j]));
    out.column_q.push_back(take_a ? a.column_q[i] : b.column_q[j]);
    for (int k = 0; k < w; ++k) {
      std::uint64_t m = 0;
      if (take_a) m |= a.column_masks[i * w + k];
      if (take_b) m |= b.column_masks[j * w + k];
      out.column_masks.push_back(m);
    }
    if (take_a) ++i;
    if (take_b) ++j;
  }
  return out;
}

}  // namespace

TemplateRotations::TemplateRotations(const VoxelTemplate& tpl, const PoseLattice& lattice)
    : name_(tpl.name), height_m_(tpl.Height()), lattice_(lattice) {
  rotations_.reserve(lattice.angle_steps);
  const std::vector<Eigen::Vector3f> points = tpl.VoxelSurfaceCentroids();
  for (int i = 0; i < lattice.angle_steps; ++i) {
    rotations_.push_back(RotatePoints(points, lattice, i));
  }
  for (int level = 1; level < kThetaLevels; ++level) {
    std::vector<RotatedTemplate> blocks;
    const int size = 1 << level;
    for (int start = 0; start < lattice.angle_steps; start += size) {
      const RotatedTemplate& left = GetBlock(level - 1, start);
      const int right_start = start + size / 2;
      blocks.push_back(right_start < lattice.angle_steps
                           ? MergeColumns(left, GetBlock(level - 1, right_start))
                           : left);
      blocks.back().itheta = start;
    }
    blocks_.push_back(std::move(blocks));
  }
}

const RotatedTemplate& TemplateRotations::GetBlock(int level, int itheta0) const {
  if (level == 0) return rotations_[itheta0];
  return blocks_[level - 1][itheta0 >> level];
}

}  // namespace hpose
