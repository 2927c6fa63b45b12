#include "core/scoring/free_space.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <utility>
#include <vector>

#include "core/depth/point_lanes.h"

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

// What the vectorised forms share: the box of columns and layers the region spans, the z terms
// of `r * centre` once per height and each lane's growth, in groups of `lanes` heights (the
// padding lanes never in the region).
struct Sweep {
  Eigen::Vector3i lo, hi;
  int groups = 0;
  // r * centre + t sums its terms in this order: ((r0 cx + r1 cy) + r2 cz) + t; the x and y
  // terms once per column, the z terms (rz0, rz1, rz2) once per height.
  Eigen::Matrix3d r;
  Eigen::Vector3d t;
  std::vector<double> rz0, rz1, rz2;
  std::vector<long long> grow;  // per lane: the layer's growth, -1 for padding.
  std::vector<int> group_grow;  // per group: its lanes' largest growth.
};

// The sweep of `region`, or false when it holds no cell or the range image is empty.
bool MakeSweep(const RangeImage& range, const Eigen::Isometry3d& sensor_from_ground,
               const FreeSpaceRegion& region, double resolution_m, int lanes, Sweep* s) {
  const int most = MostGrow(region);
  if (most < 0 || region.core_hi.x() < region.core_lo.x() ||
      region.core_hi.y() < region.core_lo.y()) {
    return false;
  }
  if (range.width() == 0 || range.height() == 0) return false;
  s->lo = Eigen::Vector3i(region.core_lo.x() - most, region.core_lo.y() - most, region.z_lo);
  s->hi = Eigen::Vector3i(region.core_hi.x() + most, region.core_hi.y() + most,
                          region.z_lo + static_cast<int>(region.grow.size()) - 1);
  s->r = sensor_from_ground.linear();
  s->t = sensor_from_ground.translation();
  const int nz = s->hi.z() - s->lo.z() + 1;
  s->groups = (nz + lanes - 1) / lanes;
  const int padded = lanes * s->groups;
  s->rz0.resize(padded);
  s->rz1.resize(padded);
  s->rz2.resize(padded);
  for (int k = 0; k < padded; ++k) {
    const double cz = (s->lo.z() + k + 0.5) * resolution_m;
    s->rz0[k] = s->r(0, 2) * cz;
    s->rz1[k] = s->r(1, 2) * cz;
    s->rz2[k] = s->r(2, 2) * cz;
  }
  s->grow.assign(padded, -1);
  for (int k = 0; k < nz; ++k) s->grow[k] = region.grow[k];
  s->group_grow.assign(s->groups, -1);
  for (int k = 0; k < nz; ++k) {
    s->group_grow[k / lanes] = std::max(s->group_grow[k / lanes], region.grow[k]);
  }
  return true;
}

#ifdef HPOSE_POINT_LANES
// Each operation rounded on its own (never fused).
using rounded::Add;
using rounded::Div;
using rounded::Mul;

// FourLanes eight heights a step: the same operations in the same order, as
// rounded AVX-512 arithmetic (never fused), the range image read by a masked gather (lanes out
// of view read nothing and are not kept), and the kept heights compressed into the column's list
// without a branch.
[[gnu::target("avx2,avx512f,avx512vl,avx512dq")]] void EightLanesAvx512(
    const Sweep& s, const RangeImage& range, const FreeSpaceRegion& region, double resolution_m,
    const FreeSpaceOptions& options, std::vector<Eigen::Vector3i>* cells) {
  const __m512d focal = _mm512_set1_pd(range.focal()), u0 = _mm512_set1_pd(range.u0());
  const __m512d v0 = _mm512_set1_pd(range.v0());
  const __m512d width = _mm512_set1_pd(range.width()), height = _mm512_set1_pd(range.height());
  const __m512d tx = _mm512_set1_pd(s.t.x()), ty = _mm512_set1_pd(s.t.y());
  const __m512d tz = _mm512_set1_pd(s.t.z());
  const __m512d margin = _mm512_set1_pd(options.margin_m);
  const __m512d sigma_factor = _mm512_set1_pd(options.sigma_factor);
  const __m512d axial = _mm512_set1_pd(1.425e-3), min_depth = _mm512_set1_pd(1e-3);
  const __m512d zero = _mm512_setzero_pd();
  const __m256i row = _mm256_set1_epi32(range.width());
  const __m256i lane_index = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const float* depth = range.depth_data();
  // One column's kept heights (a whole group's worth of slack for the last store).
  std::vector<std::int32_t> kept(8 * s.groups + 8);
  for (int x = s.lo.x(); x <= s.hi.x(); ++x) {
    const double cx = (x + 0.5) * resolution_m;
    for (int y = s.lo.y(); y <= s.hi.y(); ++y) {
      const double cy = (y + 0.5) * resolution_m;
      const __m512d a0 = _mm512_set1_pd(s.r(0, 0) * cx + s.r(0, 1) * cy);
      const __m512d a1 = _mm512_set1_pd(s.r(1, 0) * cx + s.r(1, 1) * cy);
      const __m512d a2 = _mm512_set1_pd(s.r(2, 0) * cx + s.r(2, 1) * cy);
      const int outside = OutsideCore(region, x, y);
      const __m512i outside8 = _mm512_set1_epi64(outside);
      int count = 0;
      for (int g = 0; g < s.groups; ++g) {
        if (s.group_grow[g] < outside) continue;
        const __mmask8 real = _mm512_cmpge_epi64_mask(_mm512_loadu_si512(&s.grow[8 * g]), outside8);
        const __m512d sx = Add(Add(a0, _mm512_loadu_pd(&s.rz0[8 * g])), tx);
        const __m512d sy = Add(Add(a1, _mm512_loadu_pd(&s.rz1[8 * g])), ty);
        const __m512d sz = Add(Add(a2, _mm512_loadu_pd(&s.rz2[8 * g])), tz);
        const __m512d uf = Add(Mul(Div(sx, sz), focal), u0);
        const __m512d vf = Add(Mul(Div(sy, sz), focal), v0);
        const __mmask8 inside = _mm512_mask_cmp_pd_mask(
            _mm512_mask_cmp_pd_mask(
                _mm512_mask_cmp_pd_mask(
                    _mm512_mask_cmp_pd_mask(
                        _mm512_mask_cmp_pd_mask(real, sz, min_depth, _CMP_GT_OQ), uf, zero,
                        _CMP_GE_OQ),
                    vf, zero, _CMP_GE_OQ),
                uf, width, _CMP_LT_OQ),
            vf, height, _CMP_LT_OQ);
        // Within the image the truncation is the floor, and fits an int.
        const __m256i bin =
            _mm256_add_epi32(_mm256_mullo_epi32(_mm512_maskz_cvttpd_epi32(0xFF, vf), row),
                             _mm512_maskz_cvttpd_epi32(0xFF, uf));
        const __m512d seen = _mm512_maskz_cvtps_pd(
            0xFF, _mm256_mmask_i32gather_ps(_mm256_setzero_ps(), inside, bin, depth, 4));
        const __m512d needed = Add(Add(sz, margin), Mul(sigma_factor, Mul(Mul(axial, seen), seen)));
        const __mmask8 keep = _mm512_mask_cmp_pd_mask(
            _mm512_mask_cmp_pd_mask(inside, seen, zero, _CMP_GT_OQ), seen, needed, _CMP_GT_OQ);
        // Cells are sorted (x, y, z) as VoxeliseCluster sorts them.
        const __m256i heights = _mm256_add_epi32(_mm256_set1_epi32(s.lo.z() + 8 * g), lane_index);
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(kept.data() + count),
                            _mm256_maskz_compress_epi32(keep, heights));
        count += __builtin_popcount(keep);
      }
      for (int k = 0; k < count; ++k) cells->emplace_back(x, y, kept[k]);
    }
  }
}

// The same eight heights a step on AVX2, as two vectors of four doubles: the same operations in
// the same order (this target has no fused multiply-add, and intrinsics are never contracted),
// the range image read by a masked gather of four floats per half (lanes out of view read
// nothing), and the kept heights moved to the front of eight int lanes by one permutation.
[[gnu::target("avx2")]] void EightLanesAvx2(const Sweep& s, const RangeImage& range,
                                            const FreeSpaceRegion& region, double resolution_m,
                                            const FreeSpaceOptions& options,
                                            std::vector<Eigen::Vector3i>* cells) {
  const __m256d focal = _mm256_set1_pd(range.focal()), u0 = _mm256_set1_pd(range.u0());
  const __m256d v0 = _mm256_set1_pd(range.v0());
  const __m256d width = _mm256_set1_pd(range.width()), height = _mm256_set1_pd(range.height());
  const __m256d tx = _mm256_set1_pd(s.t.x()), ty = _mm256_set1_pd(s.t.y());
  const __m256d tz = _mm256_set1_pd(s.t.z());
  const __m256d margin = _mm256_set1_pd(options.margin_m);
  const __m256d sigma_factor = _mm256_set1_pd(options.sigma_factor);
  const __m256d axial = _mm256_set1_pd(1.425e-3), min_depth = _mm256_set1_pd(1e-3);
  const __m256d zero = _mm256_setzero_pd();
  const __m128i row = _mm_set1_epi32(range.width());
  const __m256i lane_index = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const float* depth = range.depth_data();
  std::vector<std::int32_t> kept(8 * s.groups + 8);
  for (int x = s.lo.x(); x <= s.hi.x(); ++x) {
    const double cx = (x + 0.5) * resolution_m;
    for (int y = s.lo.y(); y <= s.hi.y(); ++y) {
      const double cy = (y + 0.5) * resolution_m;
      const __m256d a0 = _mm256_set1_pd(s.r(0, 0) * cx + s.r(0, 1) * cy);
      const __m256d a1 = _mm256_set1_pd(s.r(1, 0) * cx + s.r(1, 1) * cy);
      const __m256d a2 = _mm256_set1_pd(s.r(2, 0) * cx + s.r(2, 1) * cy);
      const int outside = OutsideCore(region, x, y);
      // grow >= outside, as grow > outside - 1.
      const __m256i below = _mm256_set1_epi64x(static_cast<long long>(outside) - 1);
      int count = 0;
      for (int g = 0; g < s.groups; ++g) {
        if (s.group_grow[g] < outside) continue;
        int keep_bits = 0;
        for (int half = 0; half < 2; ++half) {
          const int k = 8 * g + 4 * half;
          const __m256d real = _mm256_castsi256_pd(_mm256_cmpgt_epi64(
              _mm256_loadu_si256(reinterpret_cast<const __m256i*>(&s.grow[k])), below));
          const __m256d sx = _mm256_add_pd(_mm256_add_pd(a0, _mm256_loadu_pd(&s.rz0[k])), tx);
          const __m256d sy = _mm256_add_pd(_mm256_add_pd(a1, _mm256_loadu_pd(&s.rz1[k])), ty);
          const __m256d sz = _mm256_add_pd(_mm256_add_pd(a2, _mm256_loadu_pd(&s.rz2[k])), tz);
          const __m256d uf = _mm256_add_pd(_mm256_mul_pd(_mm256_div_pd(sx, sz), focal), u0);
          const __m256d vf = _mm256_add_pd(_mm256_mul_pd(_mm256_div_pd(sy, sz), focal), v0);
          const __m256d inside = _mm256_and_pd(
              _mm256_and_pd(_mm256_and_pd(real, _mm256_cmp_pd(sz, min_depth, _CMP_GT_OQ)),
                            _mm256_and_pd(_mm256_cmp_pd(uf, zero, _CMP_GE_OQ),
                                          _mm256_cmp_pd(vf, zero, _CMP_GE_OQ))),
              _mm256_and_pd(_mm256_cmp_pd(uf, width, _CMP_LT_OQ),
                            _mm256_cmp_pd(vf, height, _CMP_LT_OQ)));
          if (_mm256_movemask_pd(inside) == 0) continue;
          // Within the image the truncation is the floor, and fits an int; the lanes out of it
          // are not read.
          const __m128i bin =
              _mm_add_epi32(_mm_mullo_epi32(_mm256_cvttpd_epi32(vf), row), _mm256_cvttpd_epi32(uf));
          // The four 64-bit lane masks as four 32-bit ones (each half of a lane is the lane).
          const __m128 lanes32 = _mm_shuffle_ps(_mm256_castps256_ps128(_mm256_castpd_ps(inside)),
                                                _mm256_extractf128_ps(_mm256_castpd_ps(inside), 1),
                                                _MM_SHUFFLE(2, 0, 2, 0));
          const __m256d seen =
              _mm256_cvtps_pd(_mm_mask_i32gather_ps(_mm_setzero_ps(), depth, bin, lanes32, 4));
          const __m256d needed = _mm256_add_pd(
              _mm256_add_pd(sz, margin),
              _mm256_mul_pd(sigma_factor, _mm256_mul_pd(_mm256_mul_pd(axial, seen), seen)));
          const __m256d keep =
              _mm256_and_pd(_mm256_and_pd(inside, _mm256_cmp_pd(seen, zero, _CMP_GT_OQ)),
                            _mm256_cmp_pd(seen, needed, _CMP_GT_OQ));
          keep_bits |= _mm256_movemask_pd(keep) << (4 * half);
        }
        if (keep_bits == 0) continue;
        // Cells are sorted (x, y, z) as VoxeliseCluster sorts them.
        const __m256i heights = _mm256_add_epi32(_mm256_set1_epi32(s.lo.z() + 8 * g), lane_index);
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(kept.data() + count),
                            _mm256_permutevar8x32_epi32(heights, PackLanes8(keep_bits)));
        count += __builtin_popcount(keep_bits);
      }
      for (int k = 0; k < count; ++k) cells->emplace_back(x, y, kept[k]);
    }
  }
}
#endif

// FreeSpaceCellsFourLanes' pass over its sweep (four heights a group).
__attribute__((target_clones("avx2", "default"))) void FourLanes(
    const Sweep& sweep, const RangeImage& range, const FreeSpaceRegion& region, double resolution_m,
    const FreeSpaceOptions& options, std::vector<Eigen::Vector3i>* cells) {
  const Eigen::Vector3i& lo = sweep.lo;
  const Eigen::Vector3i& hi = sweep.hi;
  const Eigen::Matrix3d& r = sweep.r;
  const Eigen::Vector3d& t = sweep.t;
  const int groups = sweep.groups;
  const double focal = range.focal(), u0 = range.u0(), v0 = range.v0();
  const double width = range.width(), height = range.height();
  const int row = range.width();
  const double margin = options.margin_m, sigma_factor = options.sigma_factor;
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
        if (sweep.group_grow[g] < outside) continue;
        // Loaded by memcpy (the arrays hold plain doubles), never passed by value: a 256-bit
        // vector argument would change the calling convention between the clones.
        Double4 z0, z1, z2;
        Long4 lane_grow;
        std::memcpy(&z0, &sweep.rz0[4 * g], sizeof z0);
        std::memcpy(&z1, &sweep.rz1[4 * g], sizeof z1);
        std::memcpy(&z2, &sweep.rz2[4 * g], sizeof z2);
        std::memcpy(&lane_grow, &sweep.grow[4 * g], sizeof lane_grow);
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
      cells->insert(cells->end(), column.begin(), column.begin() + count);
    }
  }
}

// The free cells of `region` found by `pass` over its sweep in groups of `lanes` heights.
using SweepPass = void (*)(const Sweep&, const RangeImage&, const FreeSpaceRegion&, double,
                           const FreeSpaceOptions&, std::vector<Eigen::Vector3i>*);
ClusterVoxels SweepRegion(const RangeImage& range, const Eigen::Isometry3d& sensor_from_ground,
                          const FreeSpaceRegion& region, double resolution_m,
                          const FreeSpaceOptions& options, int lanes, SweepPass pass) {
  ClusterVoxels free;
  free.resolution_m = resolution_m;
  Sweep sweep;
  if (MakeSweep(range, sensor_from_ground, region, resolution_m, lanes, &sweep)) {
    pass(sweep, range, region, resolution_m, options, &free.cells);
  }
  return free;
}

}  // namespace

ClusterVoxels FreeSpaceCellsFourLanes(const RangeImage& range,
                                      const Eigen::Isometry3d& sensor_from_ground,
                                      const FreeSpaceRegion& region, double resolution_m,
                                      const FreeSpaceOptions& options) {
  return SweepRegion(range, sensor_from_ground, region, resolution_m, options, 4, FourLanes);
}

bool FreeSpaceEightLanes() { return PointLanesAvailable(); }

FreeSpaceRegion FreeSpaceRegionAround(const ClusterVoxels& voxels, std::vector<int> grow) {
  FreeSpaceRegion region;
  region.core_lo = region.core_hi = voxels.cells.front().head<2>();
  for (const Eigen::Vector3i& v : voxels.cells) {
    region.core_lo = region.core_lo.cwiseMin(v.head<2>());
    region.core_hi = region.core_hi.cwiseMax(v.head<2>());
  }
  region.z_lo = 0;
  region.grow = std::move(grow);
  return region;
}

ClusterVoxels FreeSpaceCells(const RangeImage& range, const Eigen::Isometry3d& sensor_from_ground,
                             const FreeSpaceRegion& region, double resolution_m,
                             const FreeSpaceOptions& options) {
#ifdef HPOSE_POINT_LANES
  if (FreeSpaceEightLanes()) {
    return SweepRegion(range, sensor_from_ground, region, resolution_m, options, 8,
                       EightLanesAvx512);
  }
#endif
  return FreeSpaceCellsAvx2(range, sensor_from_ground, region, resolution_m, options);
}

bool FreeSpaceAvx2Available() { return PointLanes8Available(); }

ClusterVoxels FreeSpaceCellsAvx2(const RangeImage& range,
                                 const Eigen::Isometry3d& sensor_from_ground,
                                 const FreeSpaceRegion& region, double resolution_m,
                                 const FreeSpaceOptions& options) {
#ifdef HPOSE_POINT_LANES
  if (FreeSpaceAvx2Available()) {
    return SweepRegion(range, sensor_from_ground, region, resolution_m, options, 8, EightLanesAvx2);
  }
#endif
  return FreeSpaceCellsFourLanes(range, sensor_from_ground, region, resolution_m, options);
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
