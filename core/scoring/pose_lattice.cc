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
  RotatedTemplate r;
  r.itheta = WrapAngleIndex(lattice, itheta);
  const double theta = r.itheta * lattice.angle_step_rad();
  const double c = std::cos(theta);
  const double s = std::sin(theta);
  const double q_factor = lattice.subdivisions / lattice.resolution_m;
  const double z_factor = 1.0 / lattice.resolution_m;
  r.sub_cells.reserve(tpl.voxels.size());
  r.q_min = Eigen::Vector2i(INT_MAX, INT_MAX);
  r.q_max = Eigen::Vector2i(INT_MIN, INT_MIN);
  for (const Eigen::Vector3f& v : tpl.voxels) {
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

TemplateRotations::TemplateRotations(const VoxelTemplate& tpl, const PoseLattice& lattice)
    : name_(tpl.name), height_m_(tpl.Height()), lattice_(lattice) {
  rotations_.reserve(lattice.angle_steps);
  for (int i = 0; i < lattice.angle_steps; ++i) {
    rotations_.push_back(RotateTemplate(tpl, lattice, i));
  }
}

}  // namespace hpose
