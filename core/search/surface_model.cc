#include "core/search/surface_model.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Eigenvalues>

namespace hpose {
namespace {

Eigen::Vector3i CellIndex(const Eigen::Vector3f& p, float inv) {
  return Eigen::Vector3i(static_cast<int>(std::floor(p.x() * inv)),
                         static_cast<int>(std::floor(p.y() * inv)),
                         static_cast<int>(std::floor(p.z() * inv)));
}

// Unit normal of the plane fitted to the points within `radius` of each point (the direction of
// least spread); straight up where too few neighbours exist.
std::vector<Eigen::Vector3f> PlaneNormals(const std::vector<Eigen::Vector3f>& points,
                                          float radius) {
  std::vector<Eigen::Vector3f> normals(points.size(), Eigen::Vector3f::UnitZ());
  if (points.empty()) return normals;
  const float inv = 1.0f / radius;
  // The points sorted by cell of side `radius` (x, then y, then z; by index within a cell): the
  // three cells of an (x, y) column one above the other are one range of the order, found by
  // one binary search. Cells are offset by one past the lowest, so neighbours stay >= 0.
  std::vector<Eigen::Vector3i> cell(points.size());
  Eigen::Vector3i lo = Eigen::Vector3i::Constant(INT_MAX), hi = Eigen::Vector3i::Constant(INT_MIN);
  for (size_t i = 0; i < points.size(); ++i) {
    cell[i] = CellIndex(points[i], inv);
    lo = lo.cwiseMin(cell[i]);
    hi = hi.cwiseMax(cell[i]);
  }
  const std::int64_t ny = static_cast<std::int64_t>(hi.y()) - lo.y() + 3;
  const std::int64_t nz = static_cast<std::int64_t>(hi.z()) - lo.z() + 3;
  const auto key = [&](const Eigen::Vector3i& c) {
    return ((static_cast<std::int64_t>(c.x()) - lo.x() + 1) * ny + (c.y() - lo.y() + 1)) * nz +
           (c.z() - lo.z() + 1);
  };
  std::vector<std::pair<std::int64_t, int>> sorted(points.size());
  for (size_t i = 0; i < points.size(); ++i) sorted[i] = {key(cell[i]), static_cast<int>(i)};
  std::sort(sorted.begin(), sorted.end());

  const float r2 = radius * radius;
  // Points of one cell share their neighbour cells: the nine ranges are found once per cell,
  // the points taken in cell order (each point's sums run over the same neighbours in the
  // same order as for any other order of the points).
  using Iterator = std::vector<std::pair<std::int64_t, int>>::const_iterator;
  std::pair<Iterator, Iterator> ranges[9];
  for (auto run = sorted.cbegin(); run != sorted.cend();) {
    auto run_end = run;
    while (run_end != sorted.cend() && run_end->first == run->first) ++run_end;
    const Eigen::Vector3i& c = cell[run->second];
    int r = 0;
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        const std::int64_t first = key(c + Eigen::Vector3i(dx, dy, -1));
        const std::int64_t last = first + 2;
        auto begin =
            std::lower_bound(sorted.cbegin(), sorted.cend(), std::make_pair(first, INT_MIN));
        auto end = begin;
        while (end != sorted.cend() && end->first <= last) ++end;
        ranges[r++] = {begin, end};
      }
    }
    for (; run != run_end; ++run) {
      const size_t i = static_cast<size_t>(run->second);
      const Eigen::Vector3f& p = points[i];
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      // The lower triangle of the sum of outer products (the solver reads no more).
      double xx = 0.0, yx = 0.0, zx = 0.0, yy = 0.0, zy = 0.0, zz = 0.0;
      int n = 0;
      for (const auto& [begin, end] : ranges) {
        for (auto it = begin; it != end; ++it) {
          const int j = it->second;
          if ((points[j] - p).squaredNorm() > r2) continue;
          const Eigen::Vector3d q = (points[j] - p).cast<double>();
          sum += q;
          xx += q.x() * q.x();
          yx += q.y() * q.x();
          zx += q.z() * q.x();
          yy += q.y() * q.y();
          zy += q.z() * q.y();
          zz += q.z() * q.z();
          ++n;
        }
      }
      if (n < 3) continue;
      Eigen::Matrix3d outer;
      outer << xx, yx, zx, yx, yy, zy, zx, zy, zz;
      const Eigen::Vector3d mean = sum / n;
      const Eigen::Matrix3d cov = outer / n - mean * mean.transpose();
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
      normals[i] = eig.eigenvectors().col(0).normalized().cast<float>();
    }
  }
  return normals;
}

}  // namespace

SurfaceModel::SurfaceModel(const VoxelTemplate& tpl, double spacing_m)
    : points_(tpl.SurfaceOrVoxels()),
      spacing_(tpl.surface.empty() ? tpl.resolution_m : tpl.SurfaceCellM()) {
  if (!tpl.surface.empty() && spacing_m > spacing_) {
    points_ = ReduceSurfacePoints(points_, spacing_m);
    spacing_ = spacing_m;
  }
  normals_ = PlaneNormals(points_, static_cast<float>(2.5 * spacing_));
  Finish();
  // The free limbs, marked again on the reduced surface when it was reduced.
  if (tpl.surface.empty() || tpl.free_limb.size() != tpl.surface.size()) return;
  std::vector<std::uint8_t> marks = tpl.free_limb;
  if (points_.size() != tpl.surface.size()) {
    marks = MarkSurfaceCells(points_, tpl.FreeLimbPoints(), spacing_);
  }
  const size_t marked = static_cast<size_t>(std::count(marks.begin(), marks.end(), 1));
  if (marked == 0 || marked == marks.size()) return;
  without_free_limbs_.reset(new SurfaceModel(*this, marks, 0));
  free_limb_marks_ = std::move(marks);
}

SurfaceModel::SurfaceModel(const SurfaceModel& full, const std::vector<std::uint8_t>& marks,
                           std::uint8_t keep)
    : spacing_(full.spacing_) {
  for (size_t i = 0; i < full.points_.size(); ++i) {
    if (marks[i] != keep) continue;
    points_.push_back(full.points_[i]);
    normals_.push_back(full.normals_[i]);
  }
  Finish();
}

void SurfaceModel::Finish() {
  for (const Eigen::Vector3f& p : points_) centre_ += p;
  if (!points_.empty()) centre_ /= static_cast<float>(points_.size());
  xs_.reserve(points_.size());
  ys_.reserve(points_.size());
  zs_.reserve(points_.size());
  for (const Eigen::Vector3f& p : points_) {
    xs_.push_back(p.x());
    ys_.push_back(p.y());
    zs_.push_back(p.z());
    box_lo_ = box_lo_.cwiseMin(p.cast<double>());
    box_hi_ = box_hi_.cwiseMax(p.cast<double>());
  }
}

}  // namespace hpose
