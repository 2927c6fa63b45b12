#include "core/scoring/gather_sums.h"

#include <cassert>

#include "core/common/vector_level.h"
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

void WriteRunTable(const CellRun* runs, int run_count, const std::uint64_t* masks, int cells,
                   int mask_bytes, std::uint64_t* out) {
  // The stores below write every byte up to the last mask's 8; the padding's last words are
  // zeroed first (and, in a table of a few words, the headers' words too, written after).
  const std::size_t words = RunTableWords(run_count, cells, mask_bytes);
  std::fill(out + (words > kRunTablePadding / 8 + 1 ? words - (kRunTablePadding / 8 + 1) : 0),
            out + words, 0);
  unsigned char* at = reinterpret_cast<unsigned char*>(out);
  for (int r = 0; r <= run_count; ++r, at += sizeof(RunHeaderWord)) {
    RunHeaderWord h = kRunSentinel;
    if (r < run_count) {
      const CellRun& run = runs[r];
      assert(run.len >= 1 && run.len <= 8 && run.cx >= kRunMinX && run.cx <= kRunMaxX &&
             run.cy > -kRunRowBias && run.cy < kRunRowBias - 1);
      h = RunHeader(run.cx, run.cy, run.len);
    }
    std::memcpy(at, &h, sizeof h);
  }
  for (int c = 0; c < cells; ++c, at += mask_bytes) {
    assert(MaskBytes(masks[c]) <= mask_bytes);
    StoreRunMask(at, masks[c]);
  }
}

namespace {

// A header from its bytes.
inline RunHeaderWord LoadHeader(const unsigned char* at) {
  RunHeaderWord h;
  std::memcpy(&h, at, sizeof h);
  return h;
}

// The first header of a run with cy >= cy_lo (or the sentinel), and where its masks start.
// The sums go on from there while the headers stay within RunRowsTo(cy_hi): Header() is the
// current one, Next() moves to the next run's.
struct RowRuns {
  const unsigned char* header = nullptr;
  const unsigned char* masks = nullptr;
  RunHeaderWord Header() const { return LoadHeader(header); }
  RunHeaderWord Next() {
    header += sizeof(RunHeaderWord);
    return Header();
  }
};

RowRuns RunsFromRow(const std::uint64_t* runs, int run_count, int mask_bytes, int cy_lo) {
  RowRuns out{reinterpret_cast<const unsigned char*>(runs), RunMasks(runs, run_count)};
  const RunHeaderWord from = RunRowsFrom(cy_lo);
  for (RunHeaderWord h = out.Header(); h < from; h = out.Next()) {
    out.masks += RunHeaderBytes(h, mask_bytes);
  }
  return out;
}

// The plane offset of a run's first word: base + cy * row + cx, with the biased cy of its
// header and `biased_base` = base - kRunRowBias * row.
inline std::ptrdiff_t RunOffset(std::ptrdiff_t biased_base, std::ptrdiff_t row, RunHeaderWord h) {
  return biased_base + static_cast<std::ptrdiff_t>(h >> 16) * row + RunHeaderX(h);
}

}  // namespace

HPOSE_POPCNT_CLONES
int RunPopcountSumScalar(const std::uint64_t* plane, std::ptrdiff_t base, std::ptrdiff_t row,
                         const std::uint64_t* runs, int run_count, int mask_bytes, int cy_lo,
                         int cy_hi) {
  int sum = 0;
  RowRuns rr = RunsFromRow(runs, run_count, mask_bytes, cy_lo);
  const RunHeaderWord to = RunRowsTo(cy_hi);
  const std::ptrdiff_t biased_base = base - kRunRowBias * row;
  for (RunHeaderWord h = rr.Header(); h <= to; h = rr.Next()) {
    const std::uint64_t* p = plane + RunOffset(biased_base, row, h);
    const int len = RunHeaderLength(h);
    for (int i = 0; i < len; ++i) {
      sum += __builtin_popcountll(LoadRunMask(rr.masks + i * mask_bytes, mask_bytes) & p[i]);
    }
    rr.masks += RunHeaderBytes(h, mask_bytes);
  }
  return sum;
}

HPOSE_POPCNT_CLONES
void RunPopcountSum4Scalar(const std::uint64_t* plane, std::ptrdiff_t base, std::ptrdiff_t row,
                           std::ptrdiff_t dx, std::ptrdiff_t dy, const std::uint64_t* runs,
                           int run_count, int mask_bytes, int cy_lo, int cy_hi, int out[4]) {
  int s00 = 0, s01 = 0, s10 = 0, s11 = 0;
  RowRuns rr = RunsFromRow(runs, run_count, mask_bytes, cy_lo);
  const RunHeaderWord to = RunRowsTo(cy_hi);
  const std::ptrdiff_t biased_base = base - kRunRowBias * row;
  for (RunHeaderWord h = rr.Header(); h <= to; h = rr.Next()) {
    const std::uint64_t* p = plane + RunOffset(biased_base, row, h);
    const int len = RunHeaderLength(h);
    for (int i = 0; i < len; ++i) {
      const std::uint64_t m = LoadRunMask(rr.masks + i * mask_bytes, mask_bytes);
      s00 += __builtin_popcountll(m & p[i]);
      s01 += __builtin_popcountll(m & p[i + dy]);
      s10 += __builtin_popcountll(m & p[i + dx]);
      s11 += __builtin_popcountll(m & p[i + dx + dy]);
    }
    rr.masks += RunHeaderBytes(h, mask_bytes);
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

// A run is one load of its words, masked to its lanes by its header's length (RunLanes), and one
// 64-byte load of its masks. Masks of 8 bytes are in their lanes as loaded; narrower ones are
// moved there by one byte permutation (byte j of lane l from byte l * width + j, bytes at and
// above the width zeroed). Lanes past the run hold other runs' masks, but their words are 0.
#define HPOSE_RUN_TARGET "avx512f,avx512bw,avx512vbmi,avx512vpopcntdq,popcnt"

// The permutation's byte indices per mask width (1 to 8; 0 unused).
struct LaneBytes {
  alignas(64) std::uint8_t index[9][64] = {};
  constexpr LaneBytes() {
    for (int width = 1; width <= 8; ++width) {
      for (int lane = 0; lane < 8; ++lane) {
        for (int j = 0; j < width; ++j) {
          index[width][8 * lane + j] = static_cast<std::uint8_t>(lane * width + j);
        }
      }
    }
  }
};
constexpr LaneBytes kLaneBytes;

// The bytes of a lane a mask of `mask_bytes` bytes fills, in every lane.
inline std::uint64_t LaneByteMask(int mask_bytes) {
  return 0x0101010101010101ull * ((1u << mask_bytes) - 1u);
}

// A run's lanes as a load mask: (1 << length) - 1.
[[gnu::target(HPOSE_RUN_TARGET)]] inline __mmask8 RunLanes(RunHeaderWord h) {
  return static_cast<__mmask8>((2u << (h & 7)) - 1);
}

[[gnu::target(HPOSE_RUN_TARGET)]] inline __m512i LoadRunMasks(const unsigned char* masks,
                                                              __mmask64 bytes, __m512i index,
                                                              bool packed) {
  const __m512i raw = _mm512_loadu_si512(masks);
  return packed ? _mm512_maskz_permutexvar_epi8(bytes, index, raw) : raw;
}

// What a sum over runs sets up once: where its runs start, the last row's limit, the plane
// offset of biased row 0, and the permutation that spreads masks to their lanes.
struct RunSum {
  RowRuns rr;
  RunHeaderWord to;
  std::ptrdiff_t biased_base;
  __mmask64 bytes;
  __m512i index;
};

[[gnu::target(HPOSE_RUN_TARGET)]] inline RunSum StartRunSum(std::ptrdiff_t base, std::ptrdiff_t row,
                                                            const std::uint64_t* runs,
                                                            int run_count, int mask_bytes,
                                                            int cy_lo, int cy_hi) {
  return {RunsFromRow(runs, run_count, mask_bytes, cy_lo), RunRowsTo(cy_hi),
          base - kRunRowBias * row, _cvtu64_mask64(LaneByteMask(mask_bytes)),
          _mm512_load_si512(kLaneBytes.index[mask_bytes])};
}

template <bool kPacked>
[[gnu::target(HPOSE_RUN_TARGET)]] int RunPopcountSumAvx512(const std::uint64_t* plane,
                                                           std::ptrdiff_t base, std::ptrdiff_t row,
                                                           const std::uint64_t* runs, int run_count,
                                                           int mask_bytes, int cy_lo, int cy_hi) {
  __m512i acc = _mm512_setzero_si512();
  RunSum s = StartRunSum(base, row, runs, run_count, mask_bytes, cy_lo, cy_hi);
  for (RunHeaderWord h = s.rr.Header(); h <= s.to; h = s.rr.Next()) {
    const __m512i words =
        _mm512_maskz_loadu_epi64(RunLanes(h), plane + RunOffset(s.biased_base, row, h));
    const __m512i m = LoadRunMasks(s.rr.masks, s.bytes, s.index, kPacked);
    acc = _mm512_add_epi64(acc, _mm512_popcnt_epi64(_mm512_and_si512(words, m)));
    s.rr.masks += RunHeaderBytes(h, mask_bytes);
  }
  return SumLanes(acc);
}

template <bool kPacked>
[[gnu::target(HPOSE_RUN_TARGET)]] void RunPopcountSum4Avx512(
    const std::uint64_t* plane, std::ptrdiff_t base, std::ptrdiff_t row, std::ptrdiff_t dx,
    std::ptrdiff_t dy, const std::uint64_t* runs, int run_count, int mask_bytes, int cy_lo,
    int cy_hi, int out[4]) {
  const __m512i zero = _mm512_setzero_si512();
  __m512i acc[4] = {zero, zero, zero, zero};
  const std::ptrdiff_t offset[4] = {0, dy, dx, dx + dy};
  RunSum s = StartRunSum(base, row, runs, run_count, mask_bytes, cy_lo, cy_hi);
  for (RunHeaderWord h = s.rr.Header(); h <= s.to; h = s.rr.Next()) {
    const __mmask8 k = RunLanes(h);
    const std::uint64_t* p = plane + RunOffset(s.biased_base, row, h);
    const __m512i m = LoadRunMasks(s.rr.masks, s.bytes, s.index, kPacked);
    for (int q = 0; q < 4; ++q) {
      const __m512i words = _mm512_maskz_loadu_epi64(k, p + offset[q]);
      acc[q] = _mm512_add_epi64(acc[q], _mm512_popcnt_epi64(_mm512_and_si512(words, m)));
    }
    s.rr.masks += RunHeaderBytes(h, mask_bytes);
  }
  for (int q = 0; q < 4; ++q) out[q] = SumLanes(acc[q]);
}

// AVX2 has no 64-bit popcount and no byte permutation across 128-bit halves. A run's eight
// lanes are two vectors of four: its words by masked loads (lanes past the run read as 0), its
// masks by four 16-byte loads, at the masks of lanes 0, 2, 4 and 6, each spread over its two
// lanes by a byte shuffle within its half. Bits are counted a nibble at a time by table
// lookup, and the byte counts summed into 64-bit lanes.
#define HPOSE_RUN_TARGET_AVX2 "avx2,popcnt"

// The shuffle's byte indices per mask width (1 to 8; 0 unused), the same in both halves: bytes
// of the first lane from byte j, of the second from byte width + j, 0x80 (zero) above width.
struct HalfLaneBytes {
  alignas(32) std::uint8_t index[9][32] = {};
  constexpr HalfLaneBytes() {
    for (int width = 0; width <= 8; ++width) {
      for (int half = 0; half < 2; ++half) {
        for (int lane = 0; lane < 2; ++lane) {
          for (int j = 0; j < 8; ++j) {
            index[width][16 * half + 8 * lane + j] =
                j < width ? static_cast<std::uint8_t>(lane * width + j) : 0x80;
          }
        }
      }
    }
  }
};
constexpr HalfLaneBytes kHalfLaneBytes;

// Per run length (0 to 8), the lanes' load masks: all ones in lanes below the length.
struct LengthLanes {
  alignas(32) std::int64_t lanes[9][8] = {};
  constexpr LengthLanes() {
    for (int len = 0; len <= 8; ++len) {
      for (int l = 0; l < 8; ++l) lanes[len][l] = l < len ? -1 : 0;
    }
  }
};
constexpr LengthLanes kLengthLanes;

[[gnu::target(HPOSE_RUN_TARGET_AVX2)]] inline __m256i ByteCounts(__m256i v) {
  const __m256i table = _mm256_setr_epi8(0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4, 0, 1, 1, 2,
                                         1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4);
  const __m256i nibble = _mm256_set1_epi8(0x0F);
  const __m256i lo = _mm256_and_si256(v, nibble);
  const __m256i hi = _mm256_and_si256(_mm256_srli_epi16(v, 4), nibble);
  return _mm256_add_epi8(_mm256_shuffle_epi8(table, lo), _mm256_shuffle_epi8(table, hi));
}

// The sum of the four 64-bit lanes.
[[gnu::target(HPOSE_RUN_TARGET_AVX2)]] int SumLanes(__m256i v) {
  const __m128i s = _mm_add_epi64(_mm256_castsi256_si128(v), _mm256_extracti128_si256(v, 1));
  return static_cast<int>(_mm_cvtsi128_si64(s) + _mm_extract_epi64(s, 1));
}

// A run's masks as two vectors of four lanes (masks of 8 bytes are in place as loaded).
struct RunMasks2 {
  __m256i lo, hi;
};
// The masks of lanes `lane` to lane + 3 of a run, `width` bytes each.
[[gnu::target(HPOSE_RUN_TARGET_AVX2)]] inline __m256i SpreadMasks(const unsigned char* masks,
                                                                  int lane, int width,
                                                                  __m256i index) {
  const __m128i first = _mm_loadu_si128(reinterpret_cast<const __m128i*>(masks + lane * width));
  const __m128i second =
      _mm_loadu_si128(reinterpret_cast<const __m128i*>(masks + (lane + 2) * width));
  return _mm256_shuffle_epi8(_mm256_inserti128_si256(_mm256_castsi128_si256(first), second, 1),
                             index);
}

template <bool kPacked>
[[gnu::target(HPOSE_RUN_TARGET_AVX2)]] inline RunMasks2 LoadRunMasks2(const unsigned char* masks,
                                                                      int width, __m256i index) {
  if (!kPacked) {
    return {_mm256_loadu_si256(reinterpret_cast<const __m256i*>(masks)),
            _mm256_loadu_si256(reinterpret_cast<const __m256i*>(masks + 32))};
  }
  return {SpreadMasks(masks, 0, width, index), SpreadMasks(masks, 4, width, index)};
}

// A run's words from p, zero past its length: two masked loads.
struct RunWords2 {
  __m256i lo, hi;
};
[[gnu::target(HPOSE_RUN_TARGET_AVX2)]] inline RunWords2 LoadRunWords2(const std::uint64_t* p,
                                                                      const std::int64_t* lanes) {
  const auto* q = reinterpret_cast<const long long*>(p);
  return {
      _mm256_maskload_epi64(q, _mm256_load_si256(reinterpret_cast<const __m256i*>(lanes))),
      _mm256_maskload_epi64(q + 4, _mm256_load_si256(reinterpret_cast<const __m256i*>(lanes + 4)))};
}

// The bits of (words & masks) added to acc's 64-bit lanes.
[[gnu::target(HPOSE_RUN_TARGET_AVX2)]] inline __m256i AddRunBits(__m256i acc, RunWords2 w,
                                                                 RunMasks2 m) {
  const __m256i bytes = _mm256_add_epi8(ByteCounts(_mm256_and_si256(w.lo, m.lo)),
                                        ByteCounts(_mm256_and_si256(w.hi, m.hi)));
  return _mm256_add_epi64(acc, _mm256_sad_epu8(bytes, _mm256_setzero_si256()));
}

template <bool kPacked>
[[gnu::target(HPOSE_RUN_TARGET_AVX2)]] int RunPopcountSumAvx2(
    const std::uint64_t* plane, std::ptrdiff_t base, std::ptrdiff_t row, const std::uint64_t* runs,
    int run_count, int mask_bytes, int cy_lo, int cy_hi) {
  RowRuns rr = RunsFromRow(runs, run_count, mask_bytes, cy_lo);
  const RunHeaderWord to = RunRowsTo(cy_hi);
  const std::ptrdiff_t biased_base = base - kRunRowBias * row;
  const __m256i index =
      _mm256_load_si256(reinterpret_cast<const __m256i*>(kHalfLaneBytes.index[mask_bytes]));
  __m256i acc = _mm256_setzero_si256();
  for (RunHeaderWord h = rr.Header(); h <= to; h = rr.Next()) {
    const RunWords2 w = LoadRunWords2(plane + RunOffset(biased_base, row, h),
                                      kLengthLanes.lanes[RunHeaderLength(h)]);
    acc = AddRunBits(acc, w, LoadRunMasks2<kPacked>(rr.masks, mask_bytes, index));
    rr.masks += RunHeaderBytes(h, mask_bytes);
  }
  return SumLanes(acc);
}

template <bool kPacked>
[[gnu::target(HPOSE_RUN_TARGET_AVX2)]] void RunPopcountSum4Avx2(
    const std::uint64_t* plane, std::ptrdiff_t base, std::ptrdiff_t row, std::ptrdiff_t dx,
    std::ptrdiff_t dy, const std::uint64_t* runs, int run_count, int mask_bytes, int cy_lo,
    int cy_hi, int out[4]) {
  RowRuns rr = RunsFromRow(runs, run_count, mask_bytes, cy_lo);
  const RunHeaderWord to = RunRowsTo(cy_hi);
  const std::ptrdiff_t biased_base = base - kRunRowBias * row;
  const __m256i index =
      _mm256_load_si256(reinterpret_cast<const __m256i*>(kHalfLaneBytes.index[mask_bytes]));
  const std::ptrdiff_t offset[4] = {0, dy, dx, dx + dy};
  __m256i acc[4] = {_mm256_setzero_si256(), _mm256_setzero_si256(), _mm256_setzero_si256(),
                    _mm256_setzero_si256()};
  for (RunHeaderWord h = rr.Header(); h <= to; h = rr.Next()) {
    const std::uint64_t* p = plane + RunOffset(biased_base, row, h);
    const std::int64_t* lanes = kLengthLanes.lanes[RunHeaderLength(h)];
    const RunMasks2 m = LoadRunMasks2<kPacked>(rr.masks, mask_bytes, index);
    for (int q = 0; q < 4; ++q) acc[q] = AddRunBits(acc[q], LoadRunWords2(p + offset[q], lanes), m);
    rr.masks += RunHeaderBytes(h, mask_bytes);
  }
  for (int q = 0; q < 4; ++q) out[q] = SumLanes(acc[q]);
}

bool HasAvx2RunSums() {
  static const bool has = VectorLevelAllows(VectorLevel::kAvx2) && __builtin_cpu_supports("avx2") &&
                          __builtin_cpu_supports("popcnt");
  return has;
}

bool HasAvx512Popcount() {
  static const bool has = VectorLevelAllows(VectorLevel::kAvx512) &&
                          __builtin_cpu_supports("avx512f") &&
                          __builtin_cpu_supports("avx512vpopcntdq") &&
                          __builtin_cpu_supports("avx2") && __builtin_cpu_supports("popcnt");
  return has;
}

// The run sums' vector path also needs the byte permutation (VBMI) and byte masks (BW).
bool HasAvx512RunSums() {
  static const bool has = HasAvx512Popcount() && __builtin_cpu_supports("avx512bw") &&
                          __builtin_cpu_supports("avx512vbmi");
  return has;
}

}  // namespace
#else
namespace {

// No vector paths here: the dispatch below always takes the scalar loops.
bool HasAvx512Popcount() { return false; }
bool HasAvx512RunSums() { return false; }
bool HasAvx2RunSums() { return false; }
constexpr auto* GatherPopcountSumAvx512 = &GatherPopcountSumScalar;
constexpr auto* GatherPopcountSum4Avx512 = &GatherPopcountSum4Scalar;
template <bool kPacked>
constexpr auto* RunPopcountSumAvx512 = &RunPopcountSumScalar;
template <bool kPacked>
constexpr auto* RunPopcountSum4Avx512 = &RunPopcountSum4Scalar;
template <bool kPacked>
constexpr auto* RunPopcountSumAvx2 = &RunPopcountSumScalar;
template <bool kPacked>
constexpr auto* RunPopcountSum4Avx2 = &RunPopcountSum4Scalar;

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

bool RunSumPathAvailable(RunSumPath path) {
  switch (path) {
    case RunSumPath::kScalar:
      return true;
    case RunSumPath::kAvx2:
      return HasAvx2RunSums();
    case RunSumPath::kAvx512:
      return HasAvx512RunSums();
  }
  return false;
}

RunSumPath FastestRunSumPath() {
  static const RunSumPath fastest = HasAvx512RunSums() ? RunSumPath::kAvx512
                                    : HasAvx2RunSums() ? RunSumPath::kAvx2
                                                       : RunSumPath::kScalar;
  return fastest;
}

namespace {

using RunSumFn = int (*)(const std::uint64_t*, std::ptrdiff_t, std::ptrdiff_t, const std::uint64_t*,
                         int, int, int, int);
using RunSum4Fn = void (*)(const std::uint64_t*, std::ptrdiff_t, std::ptrdiff_t, std::ptrdiff_t,
                           std::ptrdiff_t, const std::uint64_t*, int, int, int, int, int[4]);

// The loop of a path for masks of `mask_bytes` (8: as loaded; fewer: spread to their lanes).
RunSumFn RunSumOf(RunSumPath path, int mask_bytes) {
  const bool packed = mask_bytes < 8;
  switch (path) {
    case RunSumPath::kAvx512:
      return packed ? RunPopcountSumAvx512<true> : RunPopcountSumAvx512<false>;
    case RunSumPath::kAvx2:
      return packed ? RunPopcountSumAvx2<true> : RunPopcountSumAvx2<false>;
    case RunSumPath::kScalar:
      break;
  }
  return RunPopcountSumScalar;
}

RunSum4Fn RunSum4Of(RunSumPath path, int mask_bytes) {
  const bool packed = mask_bytes < 8;
  switch (path) {
    case RunSumPath::kAvx512:
      return packed ? RunPopcountSum4Avx512<true> : RunPopcountSum4Avx512<false>;
    case RunSumPath::kAvx2:
      return packed ? RunPopcountSum4Avx2<true> : RunPopcountSum4Avx2<false>;
    case RunSumPath::kScalar:
      break;
  }
  return RunPopcountSum4Scalar;
}

}  // namespace

int RunPopcountSumOn(RunSumPath path, const std::uint64_t* plane, std::ptrdiff_t base,
                     std::ptrdiff_t row, const std::uint64_t* runs, int run_count, int mask_bytes,
                     int cy_lo, int cy_hi) {
  assert(RunSumPathAvailable(path));
  return RunSumOf(path, mask_bytes)(plane, base, row, runs, run_count, mask_bytes, cy_lo, cy_hi);
}

void RunPopcountSum4On(RunSumPath path, const std::uint64_t* plane, std::ptrdiff_t base,
                       std::ptrdiff_t row, std::ptrdiff_t dx, std::ptrdiff_t dy,
                       const std::uint64_t* runs, int run_count, int mask_bytes, int cy_lo,
                       int cy_hi, int out[4]) {
  assert(RunSumPathAvailable(path));
  RunSum4Of(path, mask_bytes)(plane, base, row, dx, dy, runs, run_count, mask_bytes, cy_lo, cy_hi,
                              out);
}

int RunPopcountSum(const std::uint64_t* plane, std::ptrdiff_t base, std::ptrdiff_t row,
                   const std::uint64_t* runs, int run_count, int mask_bytes, int cy_lo, int cy_hi) {
  return RunSumOf(FastestRunSumPath(), mask_bytes)(plane, base, row, runs, run_count, mask_bytes,
                                                   cy_lo, cy_hi);
}

void RunPopcountSum4(const std::uint64_t* plane, std::ptrdiff_t base, std::ptrdiff_t row,
                     std::ptrdiff_t dx, std::ptrdiff_t dy, const std::uint64_t* runs, int run_count,
                     int mask_bytes, int cy_lo, int cy_hi, int out[4]) {
  RunSum4Of(FastestRunSumPath(), mask_bytes)(plane, base, row, dx, dy, runs, run_count, mask_bytes,
                                             cy_lo, cy_hi, out);
}

}  // namespace hpose
