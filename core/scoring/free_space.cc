#include "core/scoring/free_space.h"

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <vector>

namespace hpose {
namespace {

// Four cells of a column at once: the same operations, in the same order, as the reference's
// per-cell matrix product and RangeImage::DepthToward, so the same cells (IEEE operations round
// alike lane by lane; no fused multiply-adds at this target).
typedef double Double4 __attribute__((vector_size(32)));
typedef long long Long4 __attribute__((vector_size(32)));
typedef int Int4 __attribute__((vector_size(16)));

// The box [lo, hi] as a region: its columns, every layer, grown by nothing.
FreeSpaceRegion BoxRegion(const Eigen::Vector3i& lo, const Eigen::Vector3i& hi) {
  FreeSpaceRegion r;
  if (hi.x() < lo.x() || hi.y() < lo.y() || hi.z() < lo.z()) return r;
  r.core_lo = lo.head<2>();
  r.core_hi = hi.head<2>();
  r.z_lo = lo.z();
  r.grow.assign(hi.z() - lo.z() + 1, 0);
  return r;
}

// Cells (Chebyshev) from the column (x, y) to the region's core box; 0 inside it.
int OutsideCore(const FreeSpaceRegion& region, int x, int y) {
  return std::max({0, region.core_lo.x() - x, x - region.core_hi.x(), region.core_lo.y() - y,
                   y - region.core_hi.y()});
}

int MostGrow(const FreeSpaceRegion& region) {
  return region.grow.empty() ? -1 : *std::max_element(region.grow.begin(), region.grow.end());
}

}  // namespace

__attribute__((target_clones("avx2", "default"))) ClusterVoxels FreeSpaceCells(
    const RangeImage& range, const Eigen::Isometry3d& sensor_from_ground,
    const FreeSpaceRegion& region, double resolution_m, const FreeSpaceOptions& options) {
  ClusterVoxels free;
  free.resolution_m = resolution_m;
  const int most = MostGrow(region);
  if (most < 0 || region.core_hi.x() < region.core_lo.x() ||
      region.core_hi.y() < region.core_lo.y()) {
    return free;
  }
  if (range.width() == 0 || range.height() == 0) return free;
  const Eigen::Vector3i lo(region.core_lo.x() - most, region.core_lo.y() - most, region.z_lo);
  const Eigen::Vector3i hi(region.core_hi.x() + most, region.core_hi.y() + most,
                           region.z_lo + static_cast<int>(region.grow.size()) - 1);
  const Eigen::Matrix3d r = sensor_from_ground.linear();
  const Eigen::Vector3d t = sensor_from_ground.translation();
  // r * centre + t sums its terms in this order: ((r0 cx + r1 cy) + r2 cz) + t; the x and y
  // terms once per column, the z terms once per height (heights padded to whole groups of 4).
  const int nz = hi.z() - lo.z() + 1;
  const int groups = (nz + 3) / 4;
  std::vector<double> rz0(4 * groups), rz1(4 * groups), rz2(4 * groups);
  for (int k = 0; k < 4 * groups; ++k) {
    const double cz = (lo.z() + k + 0.5) * resolution_m;
    rz0[k] = r(0, 2) * cz;
    rz1[k] = r(1, 2) * cz;
    rz2[k] = r(2, 2) * cz;
  }
  const double focal = range.focal(), u0 = range.u0(), v0 = range.v0();
  const double width = range.width(), height = range.height();
  const int row = range.width();
  const double margin = options.margin_m, sigma_factor = options.sigma_factor;
  // Each lane's growth (the padding: none), and each group's largest.
  std::vector<long long> grow(4 * groups, -1);
  for (int k = 0; k < nz; ++k) grow[k] = region.grow[k];
  std::vector<int> group_grow(groups, -1);
  for (int k = 0; k < nz; ++k) group_grow[k / 4] = std::max(group_grow[k / 4], region.grow[k]);
  const float* depth = range.depth_data();
  std::vector<Eigen::Vector3i> column(4 * groups);  // one column's free cells.
  for (int x = lo.x(); x <= hi.x(); ++x) {
    const double cx = (x + 0.5) * resolution_m;
    for (int y = lo.y(); y <= hi.y(); ++y) {
      const double cy = (y + 0.5) * resolution_m;
      const double a0 = r(0, 0) * cx + r(0, 1) * cy;
      const double a1 = r(1, 0) * cx + r(1, 1) * cy;
      const double a2 = r(2, 0) * cx + r(2, 1) * cy;
      const int outside = OutsideCore(region, x, y);
      const Long4 outside4 = {outside, outside, outside, outside};
      int count = 0;
      for (int g = 0; g < groups; ++g) {
        if (group_grow[g] < outside) continue;
        // Loaded by memcpy (the arrays hold plain doubles), never passed by value: a 256-bit
        // vector argument would change the calling convention between the clones.
        Double4 z0, z1, z2;
        Long4 lane_grow;
        std::memcpy(&z0, &rz0[4 * g], sizeof z0);
        std::memcpy(&z1, &rz1[4 * g], sizeof z1);
        std::memcpy(&z2, &rz2[4 * g], sizeof z2);
        std::memcpy(&lane_grow, &grow[4 * g], sizeof lane_grow);
        const Long4 real = lane_grow >= outside4;  // the lanes of this column's region.
        const Double4 sx = (a0 + z0) + t.x();
        const Double4 sy = (a1 + z1) + t.y();
        const Double4 sz = (a2 + z2) + t.z();
        const Double4 uf = sx / sz * focal + u0;
        const Double4 vf = sy / sz * focal + v0;
        const Long4 inside =
            (sz > 1e-3) & (uf >= 0.0) & (vf >= 0.0) & (uf < width) & (vf < height) & real;
        // Within the image the truncation is the floor, and fits an int; out-of-view cells read
        // bin 0 and are dropped by `keep`.
        const Int4 bin =
            __builtin_convertvector(inside, Int4) &
            (__builtin_convertvector(vf, Int4) * row + __builtin_convertvector(uf, Int4));
        Double4 seen;
        for (int lane = 0; lane < 4; ++lane) seen[lane] = depth[bin[lane]];
        const Double4 needed = (sz + margin) + sigma_factor * ((1.425e-3 * seen) * seen);
        const Long4 keep = inside & (seen > 0.0) & (seen > needed);
        if ((keep[0] | keep[1] | keep[2] | keep[3]) == 0) continue;
        for (int lane = 0; lane < 4; ++lane) {
          // Cells are sorted (x, y, z) as VoxeliseCluster sorts them.
          column[count] = Eigen::Vector3i(x, y, lo.z() + 4 * g + lane);
          count += static_cast<int>(keep[lane] & 1);
        }
      }
      free.cells.insert(free.cells.end(), column.begin(), column.begin() + count);
    }
  }
  return free;
}

ClusterVoxels FreeSpaceCellsReference(const RangeImage& range,
                                      const Eigen::Isometry3d& sensor_from_ground,
                                      const FreeSpaceRegion& region, double resolution_m,
                                      const FreeSpaceOptions& options) {
  ClusterVoxels free;
  free.resolution_m = resolution_m;
  const int most = MostGrow(region);
  const Eigen::Matrix3d r = sensor_from_ground.linear();
  const Eigen::Vector3d t = sensor_from_ground.translation();
  for (int x = region.core_lo.x() - most; x <= region.core_hi.x() + most; ++x) {
    for (int y = region.core_lo.y() - most; y <= region.core_hi.y() + most; ++y) {
      for (size_t k = 0; k < region.grow.size(); ++k) {
        if (region.grow[k] < OutsideCore(region, x, y)) continue;
        const int z = region.z_lo + static_cast<int>(k);
        const Eigen::Vector3d centre((x + 0.5) * resolution_m, (y + 0.5) * resolution_m,
                                     (z + 0.5) * resolution_m);
        const Eigen::Vector3d s = r * centre + t;
        const double seen = range.DepthToward(s);
        if (seen <= 0.0) continue;
        const double sigma = 1.425e-3 * seen * seen;
        if (seen > s.z() + options.margin_m + options.sigma_factor * sigma) {
          free.cells.emplace_back(x, y, z);
        }
      }
    }
  }
  return free;
}

ClusterVoxels FreeSpaceCells(const RangeImage& range, const Eigen::Isometry3d& sensor_from_ground,
                             const Eigen::Vector3i& lo, const Eigen::Vector3i& hi,
                             double resolution_m, const FreeSpaceOptions& options) {
  return FreeSpaceCells(range, sensor_from_ground, BoxRegion(lo, hi), resolution_m, options);
}

ClusterVoxels FreeSpaceCellsReference(const RangeImage& range,
                                      const Eigen::Isometry3d& sensor_from_ground,
                                      const Eigen::Vector3i& lo, const Eigen::Vector3i& hi,
                                      double resolution_m, const FreeSpaceOptions& options) {
  return FreeSpaceCellsReference(range, sensor_from_ground, BoxRegion(lo, hi), resolution_m,
                                 options);
}

}  // namespace hpose
