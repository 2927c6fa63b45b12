#ifndef HPOSE_CORE_DEPTH_POINT_LANES_H_
#define HPOSE_CORE_DEPTH_POINT_LANES_H_

// Internal to core: sixteen points of a cloud (Eigen::Vector3f, 12 bytes each, packed) as three
// AVX-512 registers of their x, y and z, for the passes over whole clouds that take sixteen
// points a step; lane-wise arithmetic rounded operation by operation; and the one CPU check of
// core's AVX-512 passes. Only on x86-64 with GCC or Clang (HPOSE_POINT_LANES defined); the
// functions carry their own target, so they need nothing at build time, and run only where
// PointLanesAvailable().

#include "core/common/vector_level.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>

#include <cstdint>

#define HPOSE_POINT_LANES 1
#endif

namespace hpose {

// Whether this CPU runs core's AVX-512 passes (the sixteen-point passes over clouds, the grid
// clustering's distance tests, the free-space cells, the refinement's placement of template
// points): AVX-512 F, BW, DQ and VL, and AVX2 (what their targets name), at a vector level that
// allows AVX-512. Checked once.
inline bool PointLanesAvailable() {
#ifdef HPOSE_POINT_LANES
  static const bool has = VectorLevelAllows(VectorLevel::kAvx512) &&
                          __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
                          __builtin_cpu_supports("avx512dq") &&
                          __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx2");
  return has;
#else
  return false;
#endif
}

// Which form of a whole-cloud pass to run: the scalar reference, the AVX2 form whatever else the
// CPU has (for tests; it must be available), or the fastest the CPU has.
enum class LanePath { kScalar, kAvx2, kFastest };

// Whether this CPU runs the eight-point AVX2 forms of some of those passes (PointShuffles8),
// taken where it has no AVX-512 (or the vector level caps it at AVX2). Checked once.
inline bool PointLanes8Available() {
#ifdef HPOSE_POINT_LANES
  static const bool has = VectorLevelAllows(VectorLevel::kAvx2) && __builtin_cpu_supports("avx2");
  return has;
#else
  return false;
#endif
}

}  // namespace hpose

#ifdef HPOSE_POINT_LANES
namespace hpose {

// Lane-wise arithmetic each operation rounded on its own, for the passes that must equal a scalar
// reference to the bit: the _round forms, which the compiler never fuses into a multiply-add
// whatever its flags (masked forms: the unmasked ones start from an undefined register, which
// GCC 12 reports as uninitialised).
namespace rounded {
[[gnu::target("avx512f")]] inline __m512 Add(__m512 a, __m512 b) {
  return _mm512_maskz_add_round_ps(0xFFFF, a, b, _MM_FROUND_CUR_DIRECTION);
}
[[gnu::target("avx512f")]] inline __m512 Sub(__m512 a, __m512 b) {
  return _mm512_maskz_sub_round_ps(0xFFFF, a, b, _MM_FROUND_CUR_DIRECTION);
}
[[gnu::target("avx512f")]] inline __m512 Mul(__m512 a, __m512 b) {
  return _mm512_maskz_mul_round_ps(0xFFFF, a, b, _MM_FROUND_CUR_DIRECTION);
}
[[gnu::target("avx512f")]] inline __m512d Add(__m512d a, __m512d b) {
  return _mm512_maskz_add_round_pd(0xFF, a, b, _MM_FROUND_CUR_DIRECTION);
}
[[gnu::target("avx512f")]] inline __m512d Mul(__m512d a, __m512d b) {
  return _mm512_maskz_mul_round_pd(0xFF, a, b, _MM_FROUND_CUR_DIRECTION);
}
[[gnu::target("avx512f")]] inline __m512d Div(__m512d a, __m512d b) {
  return _mm512_maskz_div_round_pd(0xFF, a, b, _MM_FROUND_CUR_DIRECTION);
}
}  // namespace rounded

struct PointLanes {
  __m512 x, y, z;
};

// Lane i of x, y and z is float 3i, 3i + 1 and 3i + 2 of 48: taken from the first 32 by one
// permutation and from the last 16 by a second one. Made once per pass.
class PointDeinterleaver {
 public:
  [[gnu::target("avx512f")]] PointDeinterleaver() {
    for (int k = 0; k < 3; ++k) {
      alignas(64) std::int32_t ab[16], c[16];
      unsigned mask = 0;
      for (int i = 0; i < 16; ++i) {
        const int f = 3 * i + k;
        ab[i] = f < 32 ? f : 0;
        c[i] = f >= 32 ? f - 32 : 0;
        if (f >= 32) mask |= 1u << i;
      }
      ab_[k] = _mm512_load_si512(ab);
      c_[k] = _mm512_load_si512(c);
      from_c_[k] = static_cast<__mmask16>(mask);
    }
  }

  // The sixteen points from `p` (48 floats).
  [[gnu::target("avx512f")]] PointLanes Load(const float* p) const {
    const __m512 a = _mm512_loadu_ps(p), b = _mm512_loadu_ps(p + 16), c = _mm512_loadu_ps(p + 32);
    __m512 out[3];
    for (int k = 0; k < 3; ++k) {
      out[k] =
          _mm512_mask_permutexvar_ps(_mm512_permutex2var_ps(a, ab_[k], b), from_c_[k], c_[k], c);
    }
    return {out[0], out[1], out[2]};
  }

 private:
  __m512i ab_[3], c_[3];
  __mmask16 from_c_[3];
};

// The inverse: the first `count` lanes of x, y and z written as `count` points (3 count floats)
// from `dst`, nothing past them. Float f of the 48 is component f % 3 of lane f / 3: from x
// (index f / 3) or y (16 + f / 3) by one permutation, z by a second one into the lanes of
// component 2.
class PointInterleaver {
 public:
  [[gnu::target("avx512f")]] PointInterleaver() {
    for (int r = 0; r < 3; ++r) {
      alignas(64) std::int32_t xy[16], z[16];
      unsigned mask = 0;
      for (int l = 0; l < 16; ++l) {
        const int f = 16 * r + l, point = f / 3, c = f % 3;
        xy[l] = c == 1 ? 16 + point : point;
        z[l] = point;
        if (c == 2) mask |= 1u << l;
      }
      xy_[r] = _mm512_load_si512(xy);
      z_[r] = _mm512_load_si512(z);
      z_lanes_[r] = static_cast<__mmask16>(mask);
    }
  }

  [[gnu::target("avx512f")]] void Store(__m512 x, __m512 y, __m512 z, int count, float* dst) const {
    const int floats = 3 * count;
    for (int r = 0; r < 3; ++r) {
      const int left = floats - 16 * r;
      if (left <= 0) break;
      const __mmask16 keep =
          left >= 16 ? static_cast<__mmask16>(0xFFFF) : static_cast<__mmask16>((1u << left) - 1);
      const __m512 xy = _mm512_permutex2var_ps(x, xy_[r], y);
      _mm512_mask_storeu_ps(dst + 16 * r, keep,
                            _mm512_mask_permutexvar_ps(xy, z_lanes_[r], z_[r], z));
    }
  }

 private:
  __m512i xy_[3], z_[3];
  __mmask16 z_lanes_[3];
};

// Eight points as three AVX2 registers, for the same passes on CPUs with AVX2 but no AVX-512.
struct PointLanes8 {
  __m256 x, y, z;
};

// Lane i of x, y and z is float 3i, 3i + 1 and 3i + 2 of 24. Points 0-3 lie in the first 12
// floats and points 4-7 in the last 12, so the 128-bit halves of the three vectors of 8 floats
// exchange once (three half swaps), and each half is then a transpose of four points by
// shuffles within 128-bit lanes, as are Store's: after the swaps, vectors r0, r1, r2 hold floats
// 0-3, 4-7, 8-11 of points 0-3 in their first halves and of points 4-7 in their second.
class PointShuffles8 {
 public:
  PointShuffles8() {}  // (nothing to set up; user-provided, so const objects may be made)

  // The eight points from `p` (24 floats).
  [[gnu::target("avx2")]] PointLanes8 Load(const float* p) const {
    const __m256 m0 = _mm256_loadu_ps(p), m1 = _mm256_loadu_ps(p + 8), m2 = _mm256_loadu_ps(p + 16);
    const __m256 r0 = _mm256_permute2f128_ps(m0, m1, 0x30);  // x0 y0 z0 x1 | x4 y4 z4 x5
    const __m256 r1 = _mm256_permute2f128_ps(m0, m2, 0x21);  // y1 z1 x2 y2 | y5 z5 x6 y6
    const __m256 r2 = _mm256_permute2f128_ps(m1, m2, 0x30);  // z2 x3 y3 z3 | z6 x7 y7 z7
    const __m256 xy = _mm256_shuffle_ps(r1, r2, _MM_SHUFFLE(2, 1, 3, 2));  // x2 y2 x3 y3
    const __m256 yz = _mm256_shuffle_ps(r0, r1, _MM_SHUFFLE(1, 0, 2, 1));  // y0 z0 y1 z1
    return {_mm256_shuffle_ps(r0, xy, _MM_SHUFFLE(2, 0, 3, 0)),
            _mm256_shuffle_ps(yz, xy, _MM_SHUFFLE(3, 1, 2, 0)),
            _mm256_shuffle_ps(yz, r2, _MM_SHUFFLE(3, 0, 3, 1))};
  }

  // All eight lanes written as eight points (24 floats) from `dst`.
  [[gnu::target("avx2")]] void Store(__m256 x, __m256 y, __m256 z, float* dst) const {
    const __m256 xy = _mm256_shuffle_ps(x, y, _MM_SHUFFLE(2, 0, 2, 0));    // x0 x2 y0 y2
    const __m256 yz = _mm256_shuffle_ps(y, z, _MM_SHUFFLE(3, 1, 3, 1));    // y1 y3 z1 z3
    const __m256 zx = _mm256_shuffle_ps(z, x, _MM_SHUFFLE(3, 1, 2, 0));    // z0 z2 x1 x3
    const __m256 r0 = _mm256_shuffle_ps(xy, zx, _MM_SHUFFLE(2, 0, 2, 0));  // x0 y0 z0 x1
    const __m256 r1 = _mm256_shuffle_ps(yz, xy, _MM_SHUFFLE(3, 1, 2, 0));  // y1 z1 x2 y2
    const __m256 r2 = _mm256_shuffle_ps(zx, yz, _MM_SHUFFLE(3, 1, 3, 1));  // z2 x3 y3 z3
    _mm256_storeu_ps(dst, _mm256_permute2f128_ps(r0, r1, 0x20));
    _mm256_storeu_ps(dst + 8, _mm256_permute2f128_ps(r2, r0, 0x30));
    _mm256_storeu_ps(dst + 16, _mm256_permute2f128_ps(r1, r2, 0x31));
  }
};

// The lanes of an 8-bit mask packed to the front: for each mask, the indices of its set bits in
// order (then zeros), for a permutation that moves the lanes a pass keeps before a store.
struct PackedLanes8 {
  alignas(8) std::uint8_t index[256][8] = {};
  constexpr PackedLanes8() {
    for (int m = 0; m < 256; ++m) {
      int n = 0;
      for (int l = 0; l < 8; ++l) {
        if ((m >> l) & 1) index[m][n++] = static_cast<std::uint8_t>(l);
      }
    }
  }
};
inline constexpr PackedLanes8 kPackedLanes8;

// The permutation that packs the lanes of `mask` (8 bits) to the front.
[[gnu::target("avx2")]] inline __m256i PackLanes8(int mask) {
  return _mm256_cvtepu8_epi32(
      _mm_loadl_epi64(reinterpret_cast<const __m128i*>(kPackedLanes8.index[mask])));
}

}  // namespace hpose

#endif  // HPOSE_POINT_LANES
#endif  // HPOSE_CORE_DEPTH_POINT_LANES_H_
