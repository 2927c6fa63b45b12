#include "core/depth/ground_band.h"

#include <cassert>
#include <cstddef>

#include "core/depth/point_lanes.h"

namespace hpose {
namespace {

// Points [begin, end) of `cloud`, the scalar way, written from out[n]; returns the next free
// slot.
size_t SelectRange(const PointCloud& cloud, const GroundBand& band, size_t begin, size_t end,
                   Eigen::Vector3f* out, int* index, size_t n) {
  for (size_t i = begin; i < end; ++i) {
    const Eigen::Vector3f& p = cloud.points[i];
    if (!p.allFinite()) continue;
    const Eigen::Vector3f g = band.rotation * p + band.translation;
    if (!(g.z() >= band.z_min && g.z() <= band.z_max)) continue;
    if (!(g.x() * g.x() + g.y() * g.y() <= band.range2)) continue;
    if (index != nullptr) index[n] = static_cast<int>(i);
    out[n++] = g;
  }
  return n;
}

#ifdef HPOSE_POINT_LANES
// Products and sums each rounded on their own (never fused).
using rounded::Add;
using rounded::Mul;

// Sixteen points a step: g with Mul and Add in Eigen's order; the lanes that pass packed to the
// front and stored. The rest by SelectRange. Returns the points written.
[[gnu::target("avx512f")]] size_t SelectAvx512(const PointCloud& cloud, const GroundBand& band,
                                               Eigen::Vector3f* out, int* index) {
  const PointDeinterleaver lanes;
  const PointInterleaver points;
  __m512 r[3][3], t[3];
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) r[row][col] = _mm512_set1_ps(band.rotation(row, col));
    t[row] = _mm512_set1_ps(band.translation(row));
  }
  const __m512 z_min = _mm512_set1_ps(band.z_min), z_max = _mm512_set1_ps(band.z_max);
  const __m512 range2 = _mm512_set1_ps(band.range2);
  const __m512 zero = _mm512_setzero_ps();
  const __m512i iota = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  const size_t size = cloud.points.size();
  float* dst = out->data();
  size_t n = 0, i = 0;
  for (; i + 16 <= size; i += 16) {
    const PointLanes p = lanes.Load(cloud.points[i].data());
    // v - v is 0 exactly when v is finite.
    const __mmask16 finite = _mm512_cmp_ps_mask(_mm512_sub_ps(p.x, p.x), zero, _CMP_EQ_OQ) &
                             _mm512_cmp_ps_mask(_mm512_sub_ps(p.y, p.y), zero, _CMP_EQ_OQ) &
                             _mm512_cmp_ps_mask(_mm512_sub_ps(p.z, p.z), zero, _CMP_EQ_OQ);
    __m512 g[3];
    for (int row = 0; row < 3; ++row) {
      g[row] = Add(Add(Mul(r[row][0], p.x), Add(Mul(r[row][1], p.y), Mul(r[row][2], p.z))), t[row]);
    }
    const __mmask16 keep =
        finite & _mm512_cmp_ps_mask(g[2], z_min, _CMP_GE_OQ) &
        _mm512_cmp_ps_mask(g[2], z_max, _CMP_LE_OQ) &
        _mm512_cmp_ps_mask(Add(Mul(g[0], g[0]), Mul(g[1], g[1])), range2, _CMP_LE_OQ);
    if (keep == 0) continue;
    const int count = __builtin_popcount(keep);
    points.Store(_mm512_maskz_compress_ps(keep, g[0]), _mm512_maskz_compress_ps(keep, g[1]),
                 _mm512_maskz_compress_ps(keep, g[2]), count, dst + 3 * n);
    if (index != nullptr) {
      _mm512_mask_compressstoreu_epi32(
          index + n, keep, _mm512_add_epi32(_mm512_set1_epi32(static_cast<int>(i)), iota));
    }
    n += static_cast<size_t>(count);
  }
  return SelectRange(cloud, band, i, size, out, index, n);
}

// Eight points a step, the same operations with AVX2 (whose target has no fused multiply-add).
// The lanes that pass are packed to the front by one permutation and all eight stored: the
// output has room for a point per input point, and n <= i, so the stores stay inside it and
// what lies past the kept points is overwritten or cut.
[[gnu::target("avx2")]] size_t SelectAvx2(const PointCloud& cloud, const GroundBand& band,
                                          Eigen::Vector3f* out, int* index) {
  const PointShuffles8 shuffles;
  __m256 r[3][3], t[3];
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) r[row][col] = _mm256_set1_ps(band.rotation(row, col));
    t[row] = _mm256_set1_ps(band.translation(row));
  }
  const __m256 z_min = _mm256_set1_ps(band.z_min), z_max = _mm256_set1_ps(band.z_max);
  const __m256 range2 = _mm256_set1_ps(band.range2);
  const __m256 zero = _mm256_setzero_ps();
  const __m256i iota = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const size_t size = cloud.points.size();
  float* dst = out->data();
  size_t n = 0, i = 0;
  for (; i + 8 <= size; i += 8) {
    const PointLanes8 p = shuffles.Load(cloud.points[i].data());
    // v - v is 0 exactly when v is finite.
    const __m256 finite =
        _mm256_and_ps(_mm256_and_ps(_mm256_cmp_ps(_mm256_sub_ps(p.x, p.x), zero, _CMP_EQ_OQ),
                                    _mm256_cmp_ps(_mm256_sub_ps(p.y, p.y), zero, _CMP_EQ_OQ)),
                      _mm256_cmp_ps(_mm256_sub_ps(p.z, p.z), zero, _CMP_EQ_OQ));
    __m256 g[3];
    for (int row = 0; row < 3; ++row) {
      g[row] = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(r[row][0], p.x),
                                           _mm256_add_ps(_mm256_mul_ps(r[row][1], p.y),
                                                         _mm256_mul_ps(r[row][2], p.z))),
                             t[row]);
    }
    const __m256 in_height = _mm256_and_ps(_mm256_cmp_ps(g[2], z_min, _CMP_GE_OQ),
                                           _mm256_cmp_ps(g[2], z_max, _CMP_LE_OQ));
    const __m256 in_range = _mm256_cmp_ps(
        _mm256_add_ps(_mm256_mul_ps(g[0], g[0]), _mm256_mul_ps(g[1], g[1])), range2, _CMP_LE_OQ);
    const int keep = _mm256_movemask_ps(_mm256_and_ps(_mm256_and_ps(finite, in_height), in_range));
    if (keep == 0) continue;
    const __m256i packed = PackLanes8(keep);
    shuffles.Store(_mm256_permutevar8x32_ps(g[0], packed), _mm256_permutevar8x32_ps(g[1], packed),
                   _mm256_permutevar8x32_ps(g[2], packed), dst + 3 * n);
    if (index != nullptr) {
      const __m256i at = _mm256_add_epi32(_mm256_set1_epi32(static_cast<int>(i)), iota);
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(index + n),
                          _mm256_permutevar8x32_epi32(at, packed));
    }
    n += static_cast<size_t>(__builtin_popcount(static_cast<unsigned>(keep)));
  }
  return SelectRange(cloud, band, i, size, out, index, n);
}

#else
size_t SelectAvx512(const PointCloud& cloud, const GroundBand& band, Eigen::Vector3f* out,
                    int* index) {
  return SelectRange(cloud, band, 0, cloud.points.size(), out, index, 0);
}
constexpr auto* SelectAvx2 = &SelectAvx512;
#endif

void Select(const PointCloud& cloud, const GroundBand& band, std::vector<Eigen::Vector3f>* out,
            std::vector<int>* index, LanePath path) {
  if (cloud.points.empty()) return;  // (and no storage to point into)
  // Room for every point, then cut to those kept.
  const size_t start = out->size();
  out->resize(start + cloud.points.size());
  int* index_at = nullptr;
  if (index != nullptr) {
    index->resize(start + cloud.points.size());
    index_at = index->data() + start;
  }
  Eigen::Vector3f* out_at = out->data() + start;
  size_t n = 0;
  if (path == LanePath::kFastest && PointLanesAvailable()) {
    n = SelectAvx512(cloud, band, out_at, index_at);
  } else if (path != LanePath::kScalar && PointLanes8Available()) {
    n = SelectAvx2(cloud, band, out_at, index_at);
  } else {
    n = SelectRange(cloud, band, 0, cloud.points.size(), out_at, index_at, 0);
  }
  out->resize(start + n);
  if (index != nullptr) index->resize(start + n);
}

}  // namespace

void SelectGroundBand(const PointCloud& cloud, const GroundBand& band,
                      std::vector<Eigen::Vector3f>* out, std::vector<int>* index) {
  Select(cloud, band, out, index, LanePath::kFastest);
}

void SelectGroundBandAvx2(const PointCloud& cloud, const GroundBand& band,
                          std::vector<Eigen::Vector3f>* out, std::vector<int>* index) {
  assert(GroundBandAvx2Available());
  Select(cloud, band, out, index, LanePath::kAvx2);
}

void SelectGroundBandScalar(const PointCloud& cloud, const GroundBand& band,
                            std::vector<Eigen::Vector3f>* out, std::vector<int>* index) {
  Select(cloud, band, out, index, LanePath::kScalar);
}

bool GroundBandVectorised() { return PointLanesAvailable() || PointLanes8Available(); }

bool GroundBandAvx2Available() { return PointLanes8Available(); }

}  // namespace hpose
