#ifndef HPOSE_CORE_DEPTH_POINT_LANES_H_
#define HPOSE_CORE_DEPTH_POINT_LANES_H_

// Internal to core: sixteen points of a cloud (Eigen::Vector3f, 12 bytes each, packed) as three
// AVX-512 registers of their x, y and z, for the passes over whole clouds that take sixteen
// points a step; lane-wise arithmetic rounded operation by operation; and the one CPU check of
// core's AVX-512 passes. Only on x86-64 with GCC or Clang (HPOSE_POINT_LANES defined); the
// functions carry their own target, so they need nothing at build time, and run only where
// PointLanesAvailable().

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>

#include <cstdint>

#define HPOSE_POINT_LANES 1
#endif

namespace hpose {

// Whether this CPU runs core's AVX-512 passes (the sixteen-point passes over clouds, the grid
// clustering's distance tests, the free-space cells, the refinement's placement of template
// points): AVX-512 F, BW, DQ and VL, and AVX2 (what their targets name). Checked once.
inline bool PointLanesAvailable() {
#ifdef HPOSE_POINT_LANES
  static const bool has = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
                          __builtin_cpu_supports("avx512dq") &&
                          __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx2");
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

}  // namespace hpose

#endif  // HPOSE_POINT_LANES
#endif  // HPOSE_CORE_DEPTH_POINT_LANES_H_
