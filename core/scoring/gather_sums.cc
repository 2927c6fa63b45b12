#include "core/scoring/gather_sums.h"

#include <cassert>

#include "core/scoring/popcount_clones.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define HPOSE_GATHER_AVX512 1
#endif

namespace hpose {

HPOSE_POPCNT_CLONES
int GatherPopcountSumScalar(const std::uint64_t* data, std::ptrdiff_t base, std::ptrdiff_t row,
                            const std::int32_t* cxe, const std::int32_t* cy,
                            const std::uint64_t* masks, int n) {
  int sum = 0;
  for (int c = 0; c < n; ++c)
    sum += __builtin_popcountll(masks[c] & data[base + cy[c] * row + cxe[c]]);
  return sum;
}

HPOSE_POPCNT_CLONES
void GatherPopcountSum4Scalar(const std::uint64_t* data, std::ptrdiff_t base, std::ptrdiff_t row,
                              std::ptrdiff_t dx, std::ptrdiff_t dy, const std::int32_t* cxe,
                              const std::int32_t* cy, const std::uint64_t* masks, int n,
                              int out[4]) {
  int s00 = 0, s01 = 0, s10 = 0, s11 = 0;
  for (int c = 0; c < n; ++c) {
    const std::uint64_t* p = data + base + cy[c] * row + cxe[c];
    const std::uint64_t m = masks[c];
    s00 += __builtin_popcountll(m & p[0]);
    s01 += __builtin_popcountll(m & p[dy]);
    s10 += __builtin_popcountll(m & p[dx]);
    s11 += __builtin_popcountll(m & p[dx + dy]);
  }
  out[0] = s00;
  out[1] = s01;
  out[2] = s10;
  out[3] = s11;
}

namespace {

// The first run whose row is at least cy_lo (runs come in ascending rows), and where its masks
// start. The sums go on from there while the rows stay within cy_hi: the runs past it are not
// counted first in a pass of their own.
struct RowRuns {
  int first = 0;
  const unsigned char* masks = nullptr;
};

RowRuns RunsFromRow(const std::uint64_t* runs, int run_count, int mask_bytes, int cy_lo) {
  RowRuns out;
  out.masks = RunMasks(runs, run_count);
  while (out.first < run_count && RunHeaderY(runs[out.first]) < cy_lo) {
    out.masks += RunHeaderLength(runs[out.first]) * mask_bytes;
    ++out.first;
  }
  return out;
}

}  // namespace

HPOSE_POPCNT_CLONES
int RunPopcountSumScalar(const std::uint64_t* plane, std::ptrdiff_t base, std::ptrdiff_t row,
                         const std::uint64_t* runs, int run_count, int mask_bytes, int cy_lo,
                         int cy_hi) {
  int sum = 0;
  const RowRuns rr = RunsFromRow(runs, run_count, mask_bytes, cy_lo);
  const unsigned char* masks = rr.masks;
  for (int r = rr.first; r < run_count; ++r) {
    const std::uint64_t h = runs[r];
    if (RunHeaderY(h) > cy_hi) break;
    const std::uint64_t* p = RunStart(plane, base, row, h);
    const int len = RunHeaderLength(h);
    for (int i = 0; i < len; ++i, masks += mask_bytes) {
      sum += __builtin_popcountll(LoadRunMask(masks, mask_bytes) & p[i]);
    }
  }
  return sum;
}

HPOSE_POPCNT_CLONES
void RunPopcountSum4Scalar(const std::uint64_t* plane, std::ptrdiff_t base, std::ptrdiff_t row,
                           std::ptrdiff_t dx, std::ptrdiff_t dy, const std::uint64_t* runs,
                           int run_count, int mask_bytes, int cy_lo, int cy_hi, int out[4]) {
  int s00 = 0, s01 = 0, s10 = 0, s11 = 0;
  const RowRuns rr = RunsFromRow(runs, run_count, mask_bytes, cy_lo);
  const unsigned char* masks = rr.masks;
  for (int r = rr.first; r < run_count; ++r) {
    const std::uint64_t h = runs[r];
    if (RunHeaderY(h) > cy_hi) break;
    const int len = RunHeaderLength(h);
    const std::uint64_t* p = RunStart(plane, base, row, h);
    for (int i = 0; i < len; ++i, masks += mask_bytes) {
      const std::uint64_t m = LoadRunMask(masks, mask_bytes);
      s00 += __builtin_popcountll(m & p[i]);
      s01 += __builtin_popcountll(m & p[i + dy]);
      s10 += __builtin_popcountll(m & p[i + dx]);
      s11 += __builtin_popcountll(m & p[i + dx + dy]);
    }
  }
  out[0] = s00;
  out[1] = s01;
  out[2] = s10;
  out[3] = s11;
}

#ifdef HPOSE_GATHER_AVX512
namespace {

// The sum of the eight 64-bit lanes.
[[gnu::target("avx512f")]] int SumLanes(__m512i v) {
  alignas(64) std::int64_t lanes[8];
  _mm512_store_si512(lanes, v);
  int sum = 0;
  for (const std::int64_t x : lanes) sum += static_cast<int>(x);
  return sum;
}

// Eight columns a step: their offsets cy * row + cxe as 32-bit lanes, one gather of the eight
// words, AND with the eight masks, per-lane popcounts summed in 64-bit lanes; the remaining
// columns by the scalar loop.
[[gnu::target("avx2,avx512f,avx512vpopcntdq,popcnt")]] int GatherPopcountSumAvx512(
    const std::uint64_t* data, std::ptrdiff_t base, std::ptrdiff_t row, const std::int32_t* cxe,
    const std::int32_t* cy, const std::uint64_t* masks, int n) {
  assert(row <= INT32_MAX);
  const std::uint64_t* p = data + base;
  const __m256i rows = _mm256_set1_epi32(static_cast<int>(row));
  const __m512i zero = _mm512_setzero_si512();
  __m512i acc = zero;
  int c = 0;
  for (; c + 8 <= n; c += 8) {
    const __m256i y = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(cy + c));
    const __m256i x = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(cxe + c));
    const __m256i offsets = _mm256_add_epi32(_mm256_mullo_epi32(y, rows), x);
    const __m512i words = _mm512_mask_i32gather_epi64(zero, 0xFF, offsets, p, 8);
    const __m512i m = _mm512_loadu_si512(masks + c);
    acc = _mm512_add_epi64(acc, _mm512_popcnt_epi64(_mm512_and_si512(words, m)));
  }
  int sum = SumLanes(acc);
  for (; c < n; ++c) sum += __builtin_popcountll(masks[c] & p[cy[c] * row + cxe[c]]);
  return sum;
}

[[gnu::target("avx2,avx512f,avx512vpopcntdq,popcnt")]] void GatherPopcountSum4Avx512(
    const std::uint64_t* data, std::ptrdiff_t base, std::ptrdiff_t row, std::ptrdiff_t dx,
    std::ptrdiff_t dy, const std::int32_t* cxe, const std::int32_t* cy, const std::uint64_t* masks,
    int n, int out[4]) {
  const std::uint64_t* p = data + base;
  const __m256i rows = _mm256_set1_epi32(static_cast<int>(row));
  const __m512i zero = _mm512_setzero_si512();
  __m512i acc[4] = {zero, zero, zero, zero};
  const std::uint64_t* const at[4] = {p, p + dy, p + dx, p + dx + dy};
  int c = 0;
  for (; c + 8 <= n; c += 8) {
    const __m256i y = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(cy + c));
    const __m256i x = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(cxe + c));
    const __m256i offsets = _mm256_add_epi32(_mm256_mullo_epi32(y, rows), x);
    const __m512i m = _mm512_loadu_si512(masks + c);
    for (int k = 0; k < 4; ++k) {
      const __m512i words = _mm512_mask_i32gather_epi64(zero, 0xFF, offsets, at[k], 8);
      acc[k] = _mm512_add_epi64(acc[k], _mm512_popcnt_epi64(_mm512_and_si512(words, m)));
    }
  }
  for (int k = 0; k < 4; ++k) out[k] = SumLanes(acc[k]);
  for (; c < n; ++c) {
    const std::ptrdiff_t o = cy[c] * row + cxe[c];
    for (int k = 0; k < 4; ++k) out[k] += __builtin_popcountll(masks[c] & at[k][o]);
  }
}

// A run is one masked load of its words and one of its masks (lanes past the run read
// nothing and count 0). Masks narrower than 8 bytes are spread to the low bytes of their lanes
// by an expanding load; 8-byte ones are a plain masked load.
#define HPOSE_RUN_TARGET "avx512f,avx512bw,avx512vbmi2,avx512vpopcntdq,bmi2,popcnt"

// The lanes of a run of `len` masks, and the bytes of those lanes an expanding load of
// `mask_bytes`-byte masks fills (`lane_bytes`: the low mask_bytes bytes of every lane).
[[gnu::target(HPOSE_RUN_TARGET)]] inline __m512i LoadRunMasks(const unsigned char* masks, int len,
                                                              std::uint64_t lane_bytes,
                                                              bool packed) {
  if (!packed) {
    return _mm512_maskz_loadu_epi64(static_cast<__mmask8>((1u << len) - 1u), masks);
  }
  return _mm512_maskz_expandloadu_epi8(_bzhi_u64(lane_bytes, 8u * static_cast<unsigned>(len)),
                                       masks);
}

inline std::uint64_t LaneBytes(int mask_bytes) {
  return 0x0101010101010101ull * ((1u << mask_bytes) - 1u);
}

template <bool kPacked>
[[gnu::target(HPOSE_RUN_TARGET)]] int RunPopcountSumAvx512Of(
    const std::uint64_t* plane, std::ptrdiff_t base, std::ptrdiff_t row, const std::uint64_t* runs,
    int run_count, int mask_bytes, int cy_lo, int cy_hi) {
  __m512i acc = _mm512_setzero_si512();
  const RowRuns rr = RunsFromRow(runs, run_count, mask_bytes, cy_lo);
  const unsigned char* masks = rr.masks;
  const std::uint64_t lane_bytes = LaneBytes(mask_bytes);
  for (int r = rr.first; r < run_count; ++r) {
    const std::uint64_t h = runs[r];
    if (RunHeaderY(h) > cy_hi) break;
    const int len = RunHeaderLength(h);
    const std::uint64_t* p = RunStart(plane, base, row, h);
    const __mmask8 k = static_cast<__mmask8>((1u << len) - 1u);
    const __m512i words = _mm512_maskz_loadu_epi64(k, p);
    const __m512i m = LoadRunMasks(masks, len, lane_bytes, kPacked);
    acc = _mm512_add_epi64(acc, _mm512_popcnt_epi64(_mm512_and_si512(words, m)));
    masks += len * mask_bytes;
  }
  return SumLanes(acc);
}

int RunPopcountSumAvx512(const std::uint64_t* plane, std::ptrdiff_t base, std::ptrdiff_t row,
                         const std::uint64_t* runs, int run_count, int mask_bytes, int cy_lo,
                         int cy_hi) {
  return (mask_bytes >= 8 ? RunPopcountSumAvx512Of<false>
                          : RunPopcountSumAvx512Of<true>)(plane, base, row, runs, run_count,
                                                          mask_bytes, cy_lo, cy_hi);
}

template <bool kPacked>
[[gnu::target(HPOSE_RUN_TARGET)]] void RunPopcountSum4Avx512Of(
    const std::uint64_t* plane, std::ptrdiff_t base, std::ptrdiff_t row, std::ptrdiff_t dx,
    std::ptrdiff_t dy, const std::uint64_t* runs, int run_count, int mask_bytes, int cy_lo,
    int cy_hi, int out[4]) {
  const __m512i zero = _mm512_setzero_si512();
  __m512i acc[4] = {zero, zero, zero, zero};
  const std::ptrdiff_t offset[4] = {0, dy, dx, dx + dy};
  const RowRuns rr = RunsFromRow(runs, run_count, mask_bytes, cy_lo);
  const unsigned char* masks = rr.masks;
  const std::uint64_t lane_bytes = LaneBytes(mask_bytes);
  for (int r = rr.first; r < run_count; ++r) {
    const std::uint64_t h = runs[r];
    if (RunHeaderY(h) > cy_hi) break;
    const int len = RunHeaderLength(h);
    const std::uint64_t* p = RunStart(plane, base, row, h);
    const __mmask8 k = static_cast<__mmask8>((1u << len) - 1u);
    const __m512i m = LoadRunMasks(masks, len, lane_bytes, kPacked);
    for (int q = 0; q < 4; ++q) {
      const __m512i words = _mm512_maskz_loadu_epi64(k, p + offset[q]);
      acc[q] = _mm512_add_epi64(acc[q], _mm512_popcnt_epi64(_mm512_and_si512(words, m)));
    }
    masks += len * mask_bytes;
  }
  for (int q = 0; q < 4; ++q) out[q] = SumLanes(acc[q]);
}

void RunPopcountSum4Avx512(const std::uint64_t* plane, std::ptrdiff_t base, std::ptrdiff_t row,
                           std::ptrdiff_t dx, std::ptrdiff_t dy, const std::uint64_t* runs,
                           int run_count, int mask_bytes, int cy_lo, int cy_hi, int out[4]) {
  (mask_bytes >= 8 ? RunPopcountSum4Avx512Of<false>
                   : RunPopcountSum4Avx512Of<true>)(plane, base, row, dx, dy, runs, run_count,
                                                    mask_bytes, cy_lo, cy_hi, out);
}

bool HasAvx512Popcount() {
  static const bool has = __builtin_cpu_supports("avx512f") &&
                          __builtin_cpu_supports("avx512vpopcntdq") &&
                          __builtin_cpu_supports("avx2") && __builtin_cpu_supports("popcnt");
  return has;
}

// The run sums' vector path also needs the expanding byte loads and BZHI.
bool HasAvx512RunSums() {
  static const bool has = HasAvx512Popcount() && __builtin_cpu_supports("avx512bw") &&
                          __builtin_cpu_supports("avx512vbmi2") && __builtin_cpu_supports("bmi2");
  return has;
}

}  // namespace
#else
namespace {

// No vector paths here: the dispatch below always takes the scalar loops.
bool HasAvx512Popcount() { return false; }
bool HasAvx512RunSums() { return false; }
constexpr auto* GatherPopcountSumAvx512 = &GatherPopcountSumScalar;
constexpr auto* GatherPopcountSum4Avx512 = &GatherPopcountSum4Scalar;
constexpr auto* RunPopcountSumAvx512 = &RunPopcountSumScalar;
constexpr auto* RunPopcountSum4Avx512 = &RunPopcountSum4Scalar;

}  // namespace
#endif

bool GatherPopcountSumVectorised() { return HasAvx512Popcount(); }

int GatherPopcountSum(const std::uint64_t* data, std::ptrdiff_t base, std::ptrdiff_t row,
                      const std::int32_t* cxe, const std::int32_t* cy, const std::uint64_t* masks,
                      int n) {
  return (HasAvx512Popcount() ? GatherPopcountSumAvx512 : GatherPopcountSumScalar)(
      data, base, row, cxe, cy, masks, n);
}

void GatherPopcountSum4(const std::uint64_t* data, std::ptrdiff_t base, std::ptrdiff_t row,
                        std::ptrdiff_t dx, std::ptrdiff_t dy, const std::int32_t* cxe,
                        const std::int32_t* cy, const std::uint64_t* masks, int n, int out[4]) {
  (HasAvx512Popcount() ? GatherPopcountSum4Avx512 : GatherPopcountSum4Scalar)(
      data, base, row, dx, dy, cxe, cy, masks, n, out);
}

int RunPopcountSum(const std::uint64_t* plane, std::ptrdiff_t base, std::ptrdiff_t row,
                   const std::uint64_t* runs, int run_count, int mask_bytes, int cy_lo, int cy_hi) {
  return (HasAvx512RunSums() ? RunPopcountSumAvx512 : RunPopcountSumScalar)(
      plane, base, row, runs, run_count, mask_bytes, cy_lo, cy_hi);
}

void RunPopcountSum4(const std::uint64_t* plane, std::ptrdiff_t base, std::ptrdiff_t row,
                     std::ptrdiff_t dx, std::ptrdiff_t dy, const std::uint64_t* runs, int run_count,
                     int mask_bytes, int cy_lo, int cy_hi, int out[4]) {
  (HasAvx512RunSums() ? RunPopcountSum4Avx512 : RunPopcountSum4Scalar)(
      plane, base, row, dx, dy, runs, run_count, mask_bytes, cy_lo, cy_hi, out);
}

}  // namespace hpose
