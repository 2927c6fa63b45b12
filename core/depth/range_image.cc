#include "core/depth/range_image.h"

#include <algorithm>
#include <cassert>
#include <climits>
#include <cmath>
#include <cstdint>
#include <limits>

#include "core/depth/point_lanes.h"

namespace hpose {

namespace {

typedef float Float4 __attribute__((vector_size(16)));
typedef double Double4 __attribute__((vector_size(32)));
typedef long long Long4 __attribute__((vector_size(32)));
typedef int Int4 __attribute__((vector_size(16)));

// The nearest depth of the points in each bin: depth[v * width + u] = min(itself, z) for every
// point in front of the sensor whose bin (u, v) lies in the image. Four points a step through
// the slopes and bins, with the same operations in the same order as one point at a time
// (IEEE operations round alike lane by lane; no fused multiply-adds at this target), then the
// minimum taken lane by lane. A point not in front of the sensor (z NaN or <= 0), or whose
// slope is not finite, fails a comparison and is dropped; one infinitely far (z = +inf) would
// take min(d, inf): no change, as skipping it.
__attribute__((target_clones("avx2", "default"))) void BinNearest(const Eigen::Vector3f* points,
                                                                  size_t n, double focal, double u0,
                                                                  double v0, int width, int height,
                                                                  float* depth) {
  const double w = width, h = height;
  size_t i = 0;
  // The bins as int lanes: only while every bin fits one.
  const bool fours = static_cast<std::int64_t>(width) * height <= INT32_MAX;
  for (; fours && i + 4 <= n; i += 4) {
    Float4 x, y, z;
    for (int k = 0; k < 4; ++k) {
      x[k] = points[i + k].x();
      y[k] = points[i + k].y();
      z[k] = points[i + k].z();
    }
    const Double4 uf = __builtin_convertvector(x / z, Double4) * focal + u0;
    const Double4 vf = __builtin_convertvector(y / z, Double4) * focal + v0;
    const Long4 front = __builtin_convertvector(z > 0.0f, Long4);
    const Long4 inside = front & (uf >= 0.0) & (vf >= 0.0) & (uf < w) & (vf < h);
    if ((inside[0] | inside[1] | inside[2] | inside[3]) == 0) continue;
    // Within the image the truncation is the floor and fits an int; other lanes read bin 0.
    const Int4 bin =
        __builtin_convertvector(inside, Int4) &
        (__builtin_convertvector(vf, Int4) * width + __builtin_convertvector(uf, Int4));
    for (int k = 0; k < 4; ++k) {
      if (inside[k] == 0) continue;
      float& d = depth[bin[k]];
      d = std::min(d, z[k]);
    }
  }
  for (; i < n; ++i) {
    const Eigen::Vector3f& p = points[i];
    if (!(p.z() > 0.0f)) continue;
    const double uf = static_cast<double>(p.x() / p.z()) * focal + u0;
    const double vf = static_cast<double>(p.y() / p.z()) * focal + v0;
    if (!(uf >= 0.0 && vf >= 0.0 && uf < w && vf < h)) continue;
    float& d = depth[static_cast<size_t>(vf) * width + static_cast<size_t>(uf)];
    d = std::min(d, p.z());
  }
}

// The extent of the slopes (x / z, y / z, in float like the points) of the points in front of
// the sensor (finite, z > 0): {x lo, x hi, y lo, y hi}, +-inf reversed when there is none. Four
// points a step, branch-free over the NaN holes of an organised cloud: a point not in front of
// the sensor leaves the extent unchanged (a minimum is the same in any order).
__attribute__((target_clones("avx2", "default"))) void SlopeExtent(const Eigen::Vector3f* points,
                                                                   size_t n, float out[4]) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  const Float4 inf = {kInf, kInf, kInf, kInf};
  Float4 x_lo = inf, x_hi = -inf, y_lo = inf, y_hi = -inf;
  size_t i = 0;
  for (; i + 4 <= n; i += 4) {
    Float4 x, y, z;
    for (int k = 0; k < 4; ++k) {
      x[k] = points[i + k].x();
      y[k] = points[i + k].y();
      z[k] = points[i + k].z();
    }
    // v - v is 0 exactly when v is finite.
    const Int4 valid = (x - x == 0.0f) & (y - y == 0.0f) & (z - z == 0.0f) & (z > 0.0f);
    const Float4 tx = x / z, ty = y / z;
    x_lo = valid ? (tx < x_lo ? tx : x_lo) : x_lo;
    x_hi = valid ? (tx > x_hi ? tx : x_hi) : x_hi;
    y_lo = valid ? (ty < y_lo ? ty : y_lo) : y_lo;
    y_hi = valid ? (ty > y_hi ? ty : y_hi) : y_hi;
  }
  float e[4] = {kInf, -kInf, kInf, -kInf};
  for (int k = 0; k < 4; ++k) {
    e[0] = std::min(e[0], x_lo[k]);
    e[1] = std::max(e[1], x_hi[k]);
    e[2] = std::min(e[2], y_lo[k]);
    e[3] = std::max(e[3], y_hi[k]);
  }
  for (; i < n; ++i) {
    const Eigen::Vector3f& p = points[i];
    if (!(p.allFinite() && p.z() > 0.0f)) continue;
    const float tx = p.x() / p.z(), ty = p.y() / p.z();
    e[0] = std::min(e[0], tx);
    e[1] = std::max(e[1], tx);
    e[2] = std::min(e[2], ty);
    e[3] = std::max(e[3], ty);
  }
  for (int k = 0; k < 4; ++k) out[k] = e[k];
}

#ifdef HPOSE_POINT_LANES
// Here and below, masked forms of the conversions: the unmasked ones start from an undefined
// register, which GCC 12 reports as uninitialised.

// BinNearest sixteen points a step: the same slopes (float division), bins (the slope in
// double, times focal, plus the offset: separate roundings, never fused) and comparisons lane by
// lane; the bins' minimum then taken point by point (min_ss(z, d): z < d ? z : d, as std::min(d,
// z)). The rest by BinNearest.
[[gnu::target("avx2,avx512f,avx512dq")]] void BinNearestAvx512(const Eigen::Vector3f* points,
                                                               size_t n, double focal, double u0,
                                                               double v0, int width, int height,
                                                               float* depth) {
  const PointDeinterleaver lanes;
  const __m512d f = _mm512_set1_pd(focal), uo = _mm512_set1_pd(u0), vo = _mm512_set1_pd(v0);
  const __m512d w = _mm512_set1_pd(width), h = _mm512_set1_pd(height);
  const __m512d zero_d = _mm512_setzero_pd();
  const __m512 far = _mm512_set1_ps(std::numeric_limits<float>::infinity());
  const __m256i row = _mm256_set1_epi32(width);
  const bool sixteens = static_cast<std::int64_t>(width) * height <= INT32_MAX;
  size_t i = 0;
  alignas(64) std::int32_t bins[16];
  alignas(64) float zs[16];
  for (; sixteens && i + 16 <= n; i += 16) {
    const PointLanes p = lanes.Load(points[i].data());
    const __m512 tx = _mm512_div_ps(p.x, p.z), ty = _mm512_div_ps(p.y, p.z);
    __mmask16 inside = _mm512_cmp_ps_mask(p.z, _mm512_setzero_ps(), _CMP_GT_OQ);
    alignas(64) float slopes[2][16];
    _mm512_store_ps(slopes[0], tx);
    _mm512_store_ps(slopes[1], ty);
    for (int half = 0; half < 2; ++half) {
      constexpr int kDir = _MM_FROUND_CUR_DIRECTION;
      const __m512d uf = _mm512_maskz_add_round_pd(
          0xFF,
          _mm512_maskz_mul_round_pd(
              0xFF, _mm512_maskz_cvtps_pd(0xFF, _mm256_load_ps(slopes[0] + 8 * half)), f, kDir),
          uo, kDir);
      const __m512d vf = _mm512_maskz_add_round_pd(
          0xFF,
          _mm512_maskz_mul_round_pd(
              0xFF, _mm512_maskz_cvtps_pd(0xFF, _mm256_load_ps(slopes[1] + 8 * half)), f, kDir),
          vo, kDir);
      const unsigned in =
          _mm512_cmp_pd_mask(uf, zero_d, _CMP_GE_OQ) & _mm512_cmp_pd_mask(vf, zero_d, _CMP_GE_OQ) &
          _mm512_cmp_pd_mask(uf, w, _CMP_LT_OQ) & _mm512_cmp_pd_mask(vf, h, _CMP_LT_OQ);
      inside &= static_cast<__mmask16>(half == 0 ? (0xFF00u | in) : (0x00FFu | (in << 8)));
      const __m256i bin =
          _mm256_add_epi32(_mm256_mullo_epi32(_mm512_maskz_cvttpd_epi32(0xFF, vf), row),
                           _mm512_maskz_cvttpd_epi32(0xFF, uf));
      _mm256_store_si256(reinterpret_cast<__m256i*>(bins + 8 * half), bin);
    }
    if (inside == 0) continue;
    // Every lane, branch-free: one outside the image takes min(depth[0], inf), no change.
    _mm512_store_si512(bins, _mm512_maskz_mov_epi32(inside, _mm512_load_si512(bins)));
    _mm512_store_ps(zs, _mm512_mask_blend_ps(inside, far, p.z));
    for (int k = 0; k < 16; ++k) {
      float* dk = depth + bins[k];
      _mm_store_ss(dk, _mm_min_ss(_mm_load_ss(zs + k), _mm_load_ss(dk)));
    }
  }
  BinNearest(points + i, n - i, focal, u0, v0, width, height, depth);
}

// SlopeExtent sixteen points a step: the same slopes; the minimum and maximum of the valid
// lanes' (no NaN among them, so any order gives the same extent), then the rest by SlopeExtent.
[[gnu::target("avx512f,avx512dq")]] void SlopeExtentAvx512(const Eigen::Vector3f* points, size_t n,
                                                           float out[4]) {
  const PointDeinterleaver lanes;
  constexpr float kInf = std::numeric_limits<float>::infinity();
  __m512 x_lo = _mm512_set1_ps(kInf), x_hi = _mm512_set1_ps(-kInf);
  __m512 y_lo = x_lo, y_hi = x_hi;
  const __m512 zero = _mm512_setzero_ps();
  size_t i = 0;
  for (; i + 16 <= n; i += 16) {
    const PointLanes p = lanes.Load(points[i].data());
    // v - v is 0 exactly when v is finite.
    const __mmask16 valid = _mm512_cmp_ps_mask(_mm512_sub_ps(p.x, p.x), zero, _CMP_EQ_OQ) &
                            _mm512_cmp_ps_mask(_mm512_sub_ps(p.y, p.y), zero, _CMP_EQ_OQ) &
                            _mm512_cmp_ps_mask(_mm512_sub_ps(p.z, p.z), zero, _CMP_EQ_OQ) &
                            _mm512_cmp_ps_mask(p.z, zero, _CMP_GT_OQ);
    const __m512 tx = _mm512_div_ps(p.x, p.z), ty = _mm512_div_ps(p.y, p.z);
    x_lo = _mm512_mask_min_ps(x_lo, valid, tx, x_lo);
    x_hi = _mm512_mask_max_ps(x_hi, valid, tx, x_hi);
    y_lo = _mm512_mask_min_ps(y_lo, valid, ty, y_lo);
    y_hi = _mm512_mask_max_ps(y_hi, valid, ty, y_hi);
  }
  SlopeExtent(points + i, n - i, out);
  alignas(64) float extent[4][16];
  _mm512_store_ps(extent[0], x_lo);
  _mm512_store_ps(extent[1], x_hi);
  _mm512_store_ps(extent[2], y_lo);
  _mm512_store_ps(extent[3], y_hi);
  for (int k = 0; k < 16; ++k) {
    out[0] = std::min(out[0], extent[0][k]);
    out[1] = std::max(out[1], extent[1][k]);
    out[2] = std::min(out[2], extent[2][k]);
    out[3] = std::max(out[3], extent[3][k]);
  }
}

// BinNearest eight points a step with AVX2 (CPUs without AVX-512): the same float slopes, the
// same double products and sums (separate roundings: this target has no fused multiply-add),
// the same comparisons and truncations, lane by lane; the bins' minimum then taken point by
// point as BinNearestAvx512 does. The rest by BinNearest.
[[gnu::target("avx2")]] void BinNearestAvx2(const Eigen::Vector3f* points, size_t n, double focal,
                                            double u0, double v0, int width, int height,
                                            float* depth) {
  const PointShuffles8 lanes;
  const __m256d f = _mm256_set1_pd(focal), uo = _mm256_set1_pd(u0), vo = _mm256_set1_pd(v0);
  const __m256d w = _mm256_set1_pd(width), h = _mm256_set1_pd(height);
  const __m256d zero_d = _mm256_setzero_pd();
  const __m256 far = _mm256_set1_ps(std::numeric_limits<float>::infinity());
  const __m128i row = _mm_set1_epi32(width);
  const bool eights = static_cast<std::int64_t>(width) * height <= INT32_MAX;
  size_t i = 0;
  alignas(32) std::int32_t bins[8];
  alignas(32) float zs[8];
  for (; eights && i + 8 <= n; i += 8) {
    const PointLanes8 p = lanes.Load(points[i].data());
    const __m256 tx = _mm256_div_ps(p.x, p.z), ty = _mm256_div_ps(p.y, p.z);
    const __m256 front = _mm256_cmp_ps(p.z, _mm256_setzero_ps(), _CMP_GT_OQ);
    __m128i in_half[2];
    __m128i bin_half[2];
    for (int half = 0; half < 2; ++half) {
      const __m128 sx = half == 0 ? _mm256_castps256_ps128(tx) : _mm256_extractf128_ps(tx, 1);
      const __m128 sy = half == 0 ? _mm256_castps256_ps128(ty) : _mm256_extractf128_ps(ty, 1);
      const __m256d uf = _mm256_add_pd(_mm256_mul_pd(_mm256_cvtps_pd(sx), f), uo);
      const __m256d vf = _mm256_add_pd(_mm256_mul_pd(_mm256_cvtps_pd(sy), f), vo);
      const __m256d in = _mm256_and_pd(
          _mm256_and_pd(_mm256_cmp_pd(uf, zero_d, _CMP_GE_OQ),
                        _mm256_cmp_pd(vf, zero_d, _CMP_GE_OQ)),
          _mm256_and_pd(_mm256_cmp_pd(uf, w, _CMP_LT_OQ), _mm256_cmp_pd(vf, h, _CMP_LT_OQ)));
      // The four 64-bit masks as four 32-bit ones (their low halves).
      const __m256i in32 = _mm256_permutevar8x32_epi32(_mm256_castpd_si256(in),
                                                       _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6));
      in_half[half] = _mm256_castsi256_si128(in32);
      bin_half[half] =
          _mm_add_epi32(_mm_mullo_epi32(_mm256_cvttpd_epi32(vf), row), _mm256_cvttpd_epi32(uf));
    }
    const __m256 inside =
        _mm256_and_ps(front, _mm256_castsi256_ps(_mm256_set_m128i(in_half[1], in_half[0])));
    if (_mm256_movemask_ps(inside) == 0) continue;
    // Every lane, branch-free: one outside the image takes min(depth[0], inf), no change.
    _mm256_store_si256(
        reinterpret_cast<__m256i*>(bins),
        _mm256_and_si256(_mm256_set_m128i(bin_half[1], bin_half[0]), _mm256_castps_si256(inside)));
    _mm256_store_ps(zs, _mm256_blendv_ps(far, p.z, inside));
    for (int k = 0; k < 8; ++k) {
      float* dk = depth + bins[k];
      _mm_store_ss(dk, _mm_min_ss(_mm_load_ss(zs + k), _mm_load_ss(dk)));
    }
  }
  BinNearest(points + i, n - i, focal, u0, v0, width, height, depth);
}

// SlopeExtent eight points a step with AVX2: the same slopes; the minimum and maximum of the
// valid lanes' (min_ps(t, lo) is t < lo ? t : lo, as SlopeExtent's), then the rest by
// SlopeExtent.
[[gnu::target("avx2")]] void SlopeExtentAvx2(const Eigen::Vector3f* points, size_t n,
                                             float out[4]) {
  const PointShuffles8 lanes;
  constexpr float kInf = std::numeric_limits<float>::infinity();
  __m256 x_lo = _mm256_set1_ps(kInf), x_hi = _mm256_set1_ps(-kInf);
  __m256 y_lo = x_lo, y_hi = x_hi;
  const __m256 zero = _mm256_setzero_ps();
  size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    const PointLanes8 p = lanes.Load(points[i].data());
    // v - v is 0 exactly when v is finite.
    const __m256 valid =
        _mm256_and_ps(_mm256_and_ps(_mm256_cmp_ps(_mm256_sub_ps(p.x, p.x), zero, _CMP_EQ_OQ),
                                    _mm256_cmp_ps(_mm256_sub_ps(p.y, p.y), zero, _CMP_EQ_OQ)),
                      _mm256_and_ps(_mm256_cmp_ps(_mm256_sub_ps(p.z, p.z), zero, _CMP_EQ_OQ),
                                    _mm256_cmp_ps(p.z, zero, _CMP_GT_OQ)));
    const __m256 tx = _mm256_div_ps(p.x, p.z), ty = _mm256_div_ps(p.y, p.z);
    x_lo = _mm256_blendv_ps(x_lo, _mm256_min_ps(tx, x_lo), valid);
    x_hi = _mm256_blendv_ps(x_hi, _mm256_max_ps(tx, x_hi), valid);
    y_lo = _mm256_blendv_ps(y_lo, _mm256_min_ps(ty, y_lo), valid);
    y_hi = _mm256_blendv_ps(y_hi, _mm256_max_ps(ty, y_hi), valid);
  }
  SlopeExtent(points + i, n - i, out);
  alignas(32) float extent[4][8];
  _mm256_store_ps(extent[0], x_lo);
  _mm256_store_ps(extent[1], x_hi);
  _mm256_store_ps(extent[2], y_lo);
  _mm256_store_ps(extent[3], y_hi);
  for (int k = 0; k < 8; ++k) {
    out[0] = std::min(out[0], extent[0][k]);
    out[1] = std::max(out[1], extent[1][k]);
    out[2] = std::min(out[2], extent[2][k]);
    out[3] = std::max(out[3], extent[3][k]);
  }
}

#else
constexpr auto* BinNearestAvx512 = &BinNearest;
constexpr auto* SlopeExtentAvx512 = &SlopeExtent;
constexpr auto* BinNearestAvx2 = &BinNearest;
constexpr auto* SlopeExtentAvx2 = &SlopeExtent;
#endif

}  // namespace

RangeImage RangeImage::Build(const PointCloud& cloud, double focal_px, Lanes lanes,
                             const ViewSpan& at_least) {
  RangeImage r;
  r.focal_ = focal_px;
  constexpr double kMaxTan = 3.0;
  constexpr float kInf = std::numeric_limits<float>::infinity();
  float extent[4];
  (lanes == Lanes::kSixteen ? SlopeExtentAvx512
   : lanes == Lanes::kEight ? SlopeExtentAvx2
                            : SlopeExtent)(cloud.points.data(), cloud.points.size(), extent);
  const float tx_lo_f = extent[0], tx_hi_f = extent[1], ty_lo_f = extent[2], ty_hi_f = extent[3];
  if (!(tx_lo_f <= tx_hi_f)) return r;  // no point in front of the sensor.
  // The points' extent, widened to the known edges (a NaN edge fails both comparisons).
  const auto lower = [](double points, double edge) { return edge < points ? edge : points; };
  const auto upper = [](double points, double edge) { return edge > points ? edge : points; };
  const double tx_lo = std::clamp<double>(lower(tx_lo_f, at_least.left), -kMaxTan, kMaxTan);
  const double tx_hi = std::clamp<double>(upper(tx_hi_f, at_least.right), -kMaxTan, kMaxTan);
  const double ty_lo = std::clamp<double>(lower(ty_lo_f, at_least.top), -kMaxTan, kMaxTan);
  const double ty_hi = std::clamp<double>(upper(ty_hi_f, at_least.bottom), -kMaxTan, kMaxTan);
  r.u0_ = -tx_lo * focal_px;
  r.v0_ = -ty_lo * focal_px;
  r.width_ = static_cast<int>((tx_hi - tx_lo) * focal_px) + 1;
  r.height_ = static_cast<int>((ty_hi - ty_lo) * focal_px) + 1;
  // Nearest depth per bin, +inf while empty (0 = unknown once done).
  r.depth_.assign(static_cast<size_t>(r.width_) * r.height_, kInf);
  (lanes == Lanes::kSixteen ? BinNearestAvx512
   : lanes == Lanes::kEight ? BinNearestAvx2
                            : BinNearest)(cloud.points.data(), cloud.points.size(), focal_px, r.u0_,
                                          r.v0_, r.width_, r.height_, r.depth_.data());
  for (float& d : r.depth_) d = d == kInf ? 0.0f : d;
  return r;
}

namespace {

// Whether the ray of slopes (tx, ty) points at least asin(sqrt(`sin2_down`)) below the horizon:
// its ground z, the linear a = g . (tx, ty, 1) with g the ground frame's z row, is negative and
// a^2 >= sin^2(down) (tx^2 + ty^2 + 1).
bool SteepRay(const Eigen::Vector3d& g, double sin2_down, double tx, double ty) {
  const double a = g.x() * tx + g.y() * ty + g.z();
  return a < 0.0 && a * a >= sin2_down * (tx * tx + ty * ty + 1.0);
}

// sin^2 of a ray's least angle below the horizon to count as steep (straight down at most).
double Sin2Down(double min_down_rad) {
  const double s = std::sin(std::min(min_down_rad, M_PI / 2.0));
  return s * s;
}

}  // namespace

bool RangeImage::HasSteepRays(const Eigen::Isometry3d& ground_from_sensor,
                              double min_down_rad) const {
  if (depth_.empty()) return false;
  const Eigen::Matrix3d r = ground_from_sensor.linear();
  const Eigen::Vector3d g = r.row(2).transpose();
  const double s2 = Sin2Down(min_down_rad);
  const auto steep = [&](int u, int v) {
    return SteepRay(g, s2, (u + 0.5 - u0_) / focal_, (v + 0.5 - v0_) / focal_);
  };
  // The image is a convex patch of the sphere of directions (a pinhole's rays to a rectangle),
  // so the ray nearest straight down is straight down itself when that falls within the image,
  // else one on the image's border.
  const Eigen::Vector3d down = r.transpose() * Eigen::Vector3d(0.0, 0.0, -1.0);  // sensor frame.
  if (down.z() > 0.0) {
    const double u = down.x() / down.z() * focal_ + u0_, v = down.y() / down.z() * focal_ + v0_;
    if (u >= 0.0 && v >= 0.0 && u < width_ && v < height_) return true;
  }
  for (int u = 0; u < width_; ++u) {
    if (steep(u, 0) || steep(u, height_ - 1)) return true;
  }
  for (int v = 0; v < height_; ++v) {
    if (steep(0, v) || steep(width_ - 1, v)) return true;
  }
  return false;
}

RangeImage RangeImage::NearestAroundSteepRays(const Eigen::Isometry3d& ground_from_sensor,
                                              double min_down_rad) const {
  RangeImage out = *this;
  const int w = width_, h = height_;
  if (w == 0 || h == 0) return out;
  // The 3 x 3 minimum as a minimum over three bins of a row, then over three rows; unknown bins
  // (0) as infinitely far.
  constexpr float kFar = std::numeric_limits<float>::infinity();
  const auto known = [&](int x, int y) {
    const float d = depth_[static_cast<size_t>(y) * w + x];
    return d > 0.0f ? d : kFar;
  };
  std::vector<float> rows(static_cast<size_t>(w) * h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      float m = known(x, y);
      if (x > 0) m = std::min(m, known(x - 1, y));
      if (x + 1 < w) m = std::min(m, known(x + 1, y));
      rows[static_cast<size_t>(y) * w + x] = m;
    }
  }
  const Eigen::Vector3d g = ground_from_sensor.linear().row(2).transpose();
  const double s2 = Sin2Down(min_down_rad);
  for (int v = 0; v < h; ++v) {
    const double ty = (v + 0.5 - v0_) / focal_;
    const float* above = rows.data() + static_cast<size_t>(std::max(0, v - 1)) * w;
    const float* here = rows.data() + static_cast<size_t>(v) * w;
    const float* below = rows.data() + static_cast<size_t>(std::min(h - 1, v + 1)) * w;
    for (int u = 0; u < w; ++u) {
      const size_t i = static_cast<size_t>(v) * w + u;
      if (!(depth_[i] > 0.0f)) continue;
      if (!SteepRay(g, s2, (u + 0.5 - u0_) / focal_, ty)) continue;
      out.depth_[i] = std::min({here[u], above[u], below[u]});
    }
  }
  return out;
}

RangeImage RangeImage::FromCloud(const PointCloud& cloud, double focal_px,
                                 const ViewSpan& at_least) {
  return Build(cloud, focal_px,
               PointLanesAvailable()    ? Lanes::kSixteen
               : PointLanes8Available() ? Lanes::kEight
                                        : Lanes::kFour,
               at_least);
}

RangeImage RangeImage::FromCloudFourLanes(const PointCloud& cloud, double focal_px,
                                          const ViewSpan& at_least) {
  return Build(cloud, focal_px, Lanes::kFour, at_least);
}

RangeImage RangeImage::FromCloudEightLanes(const PointCloud& cloud, double focal_px) {
  assert(EightLanes());
  return Build(cloud, focal_px, Lanes::kEight, {});
}

bool RangeImage::SixteenLanes() { return PointLanesAvailable(); }

bool RangeImage::EightLanes() { return PointLanes8Available(); }

bool RangeImage::Covers(const Eigen::Vector3d& p) const {
  return p.z() > 1e-3 && CoversRay(p.x() / p.z(), p.y() / p.z());
}

float RangeImage::NearestAround(const Eigen::Vector3d& p, int radius) const {
  if (!Covers(p)) return 0.0f;
  return NearestAroundRay(p.x() / p.z(), p.y() / p.z(), radius);
}

}  // namespace hpose
