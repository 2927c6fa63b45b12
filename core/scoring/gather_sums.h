#ifndef HPOSE_CORE_SCORING_GATHER_SUMS_H_
#define HPOSE_CORE_SCORING_GATHER_SUMS_H_

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace hpose {

// The sum over c in [0, n) of popcount(masks[c] & data[base + cy[c] * row + cxe[c]]): one
// masked lookup per template column or cell group, the inner loop of the exact search's values
// and bounds (ColumnOccupancy's aligned path). Every offset cy[c] * row + cxe[c] must fit in 32
// bits (occupancy boxes are a few hundred cells a side).
//
// GatherPopcountSum takes eight lookups at a time with AVX-512 gathers and 64-bit popcounts
// where the CPU has them (GatherPopcountSumVectorised()), and the scalar loop otherwise;
// GatherPopcountSumScalar is that loop, the reference. Integer sums, so both are equal.
int GatherPopcountSum(const std::uint64_t* data, std::ptrdiff_t base, std::ptrdiff_t row,
                      const std::int32_t* cxe, const std::int32_t* cy, const std::uint64_t* masks,
                      int n);
int GatherPopcountSumScalar(const std::uint64_t* data, std::ptrdiff_t base, std::ptrdiff_t row,
                            const std::int32_t* cxe, const std::int32_t* cy,
                            const std::uint64_t* masks, int n);
// GatherPopcountSum at base, base + dy, base + dx and base + dx + dy into out[0], out[1], out[2]
// and out[3] (the four blocks of a bound a whole number of cells apart), in one pass; the same
// dispatch, and the scalar reference.
void GatherPopcountSum4(const std::uint64_t* data, std::ptrdiff_t base, std::ptrdiff_t row,
                        std::ptrdiff_t dx, std::ptrdiff_t dy, const std::int32_t* cxe,
                        const std::int32_t* cy, const std::uint64_t* masks, int n, int out[4]);
void GatherPopcountSum4Scalar(const std::uint64_t* data, std::ptrdiff_t base, std::ptrdiff_t row,
                              std::ptrdiff_t dx, std::ptrdiff_t dy, const std::int32_t* cxe,
                              const std::int32_t* cy, const std::uint64_t* masks, int n,
                              int out[4]);
bool GatherPopcountSumVectorised();

// Runs of consecutive cells in one array of words (CellGroups): a 4-byte header per run, a
// sentinel header, then the masks of every run's cells, run after run, each in the same number
// of bytes (1 to 8: the table's mask width, which its template's highest z bit sets), lowest
// byte first, then padding (RunTableWords). One array read front to back: a table costs the
// cache lines it fills, not a miss per field, and a template 37 cells tall fills 5 bytes a cell
// instead of 8. A header holds what the sums use:
//   bits 0-2    the run's length - 1 (lengths 1 to 8);
//   bits 3-15   its first cell's cx, 13-bit two's complement (-4096 to 4095);
//   bits 16-31  its cy + 32768 (cy from -32767 to 32766), so that headers compare as their
//               rows do (runs come in ascending cy: CellGroups' order), and none is 0.
// The sentinel's row field is 0xFFFF, above every run's: a loop over the runs of rows up to
// some cy stops there without counting them. Headers are read with RunHeaderAt (byte copies:
// the table's storage is words).
using RunHeaderWord = std::uint32_t;
constexpr int kRunRowBias = 32768;
constexpr int kRunMinX = -4096, kRunMaxX = 4095;
constexpr RunHeaderWord kRunSentinel = RunHeaderWord{0xFFFF} << 16;
inline RunHeaderWord RunHeader(int cx, int cy, int len) {
  return static_cast<RunHeaderWord>(len - 1) | (static_cast<RunHeaderWord>(cx & 0x1FFF) << 3) |
         (static_cast<RunHeaderWord>(cy + kRunRowBias) << 16);
}
inline int RunHeaderX(RunHeaderWord h) {  // bits 3-15 moved to the top, shifted back signed.
  return static_cast<std::int32_t>(h << 16) >> 19;
}
inline int RunHeaderY(RunHeaderWord h) { return static_cast<int>(h >> 16) - kRunRowBias; }
inline int RunHeaderLength(RunHeaderWord h) { return static_cast<int>(h & 7) + 1; }
// The bytes of the run's masks (where the next run's start), at mask_bytes a mask.
inline int RunHeaderBytes(RunHeaderWord h, int mask_bytes) {
  return RunHeaderLength(h) * mask_bytes;
}
// Header r of a table (r == run count: the sentinel).
inline RunHeaderWord RunHeaderAt(const std::uint64_t* table, int r) {
  RunHeaderWord h;
  std::memcpy(&h, reinterpret_cast<const unsigned char*>(table) + sizeof h * r, sizeof h);
  return h;
}
// Every header of a run with cy >= cy_lo is at least RunRowsFrom(cy_lo), and every header of a
// run with cy <= cy_hi (and no other, nor the sentinel) at most RunRowsTo(cy_hi).
inline RunHeaderWord RunRowsFrom(int cy_lo) {
  if (cy_lo <= -kRunRowBias) return 0;
  return static_cast<RunHeaderWord>(std::min(cy_lo, kRunRowBias - 1) + kRunRowBias) << 16;
}
inline RunHeaderWord RunRowsTo(int cy_hi) {
  if (cy_hi <= -kRunRowBias) return 0;  // no header is 0.
  return (static_cast<RunHeaderWord>(std::min(cy_hi, kRunRowBias - 2) + kRunRowBias) << 16) |
         0xFFFF;
}
// The bytes a mask needs: those up to its highest set bit (at least 1).
inline int MaskBytes(std::uint64_t mask) {
  return mask == 0 ? 1 : (64 - __builtin_clzll(mask) + 7) / 8;
}
// A table's padding after its masks: 64 bytes can be read at any run's first mask.
constexpr int kRunTablePadding = 64;
// The words a table of `runs` runs and `cells` cells takes at `mask_bytes` a mask: headers,
// sentinel, masks and padding.
inline std::size_t RunTableWords(int runs, int cells, int mask_bytes) {
  const std::size_t bytes = sizeof(RunHeaderWord) * (static_cast<std::size_t>(runs) + 1) +
                            static_cast<std::size_t>(cells) * static_cast<std::size_t>(mask_bytes) +
                            kRunTablePadding;
  return (bytes + 7) / 8;
}
// Where the masks of a table of `run_count` runs start.
inline const unsigned char* RunMasks(const std::uint64_t* runs, int run_count) {
  return reinterpret_cast<const unsigned char*>(runs) +
         sizeof(RunHeaderWord) * (static_cast<std::size_t>(run_count) + 1);
}
// A run as a table's builder gives it: its first cell and its length (1 to 8).
struct CellRun {
  int cx = 0;
  int cy = 0;
  int len = 0;
};
// Lays out the table of `run_count` runs (ascending cy) and their `cells` masks (cell after
// cell, each fitting `mask_bytes` bytes) in `out`, RunTableWords(run_count, cells, mask_bytes)
// words.
void WriteRunTable(const CellRun* runs, int run_count, const std::uint64_t* masks, int cells,
                   int mask_bytes, std::uint64_t* out);
// Writes a mask at `at` as 8 bytes, lowest first: its own (it must fit the table's width) and
// zeros above, which the next mask overwrites (the padding leaves room after the last). And
// reads one back from there.
inline void StoreRunMask(unsigned char* at, std::uint64_t mask) {
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__
  mask = __builtin_bswap64(mask);
#endif
  std::memcpy(at, &mask, sizeof mask);
}
inline std::uint64_t LoadRunMask(const unsigned char* at, int mask_bytes) {
  std::uint64_t m;
  std::memcpy(&m, at, sizeof m);  // the padding makes 8 bytes readable.
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__
  m = __builtin_bswap64(m);
#endif
  return mask_bytes >= 8 ? m : m & ((std::uint64_t{1} << (8 * mask_bytes)) - 1);
}

// The same sum over such runs (`runs`: a table as above, of run_count runs, `mask_bytes` bytes a
// mask): a run adds popcount(mask & word) for its masks and the words from
// plane + base + cy * row + cx on. Runs whose cy lies outside [cy_lo, cy_hi] are left out: the
// caller passes the rows where the plane may be non-zero (INT_MIN and INT_MAX for all), so a
// small cluster's sum skips the runs that would only read zeros. It takes the fastest path
// this CPU has (FastestRunSumPath): with AVX-512 (F, BW, VBMI, VPOPCNTDQ) a run is a masked
// load of its words and a load of its masks, spread to their lanes by one byte permutation;
// with AVX2, two masked loads of four words, four 16-byte loads of masks spread by byte
// shuffles, and bits counted by nibble lookup. The scalar loop is the reference; all count the
// same integers.
int RunPopcountSum(const std::uint64_t* plane, std::ptrdiff_t base, std::ptrdiff_t row,
                   const std::uint64_t* runs, int run_count, int mask_bytes, int cy_lo, int cy_hi);
int RunPopcountSumScalar(const std::uint64_t* plane, std::ptrdiff_t base, std::ptrdiff_t row,
                         const std::uint64_t* runs, int run_count, int mask_bytes, int cy_lo,
                         int cy_hi);
// RunPopcountSum at base, base + dy, base + dx and base + dx + dy into out[0 .. 3]; runs whose
// cy lies outside [cy_lo, cy_hi] are left out of all four.
void RunPopcountSum4(const std::uint64_t* plane, std::ptrdiff_t base, std::ptrdiff_t row,
                     std::ptrdiff_t dx, std::ptrdiff_t dy, const std::uint64_t* runs, int run_count,
                     int mask_bytes, int cy_lo, int cy_hi, int out[4]);
void RunPopcountSum4Scalar(const std::uint64_t* plane, std::ptrdiff_t base, std::ptrdiff_t row,
                           std::ptrdiff_t dx, std::ptrdiff_t dy, const std::uint64_t* runs,
                           int run_count, int mask_bytes, int cy_lo, int cy_hi, int out[4]);

// The run sums' paths by name, for tests and benchmarks: whether this CPU has one, the one
// RunPopcountSum takes, and the two sums on a given path (which must be available).
enum class RunSumPath { kScalar, kAvx2, kAvx512 };
bool RunSumPathAvailable(RunSumPath path);
RunSumPath FastestRunSumPath();
int RunPopcountSumOn(RunSumPath path, const std::uint64_t* plane, std::ptrdiff_t base,
                     std::ptrdiff_t row, const std::uint64_t* runs, int run_count, int mask_bytes,
                     int cy_lo, int cy_hi);
void RunPopcountSum4On(RunSumPath path, const std::uint64_t* plane, std::ptrdiff_t base,
                       std::ptrdiff_t row, std::ptrdiff_t dx, std::ptrdiff_t dy,
                       const std::uint64_t* runs, int run_count, int mask_bytes, int cy_lo,
                       int cy_hi, int out[4]);

}  // namespace hpose

#endif  // HPOSE_CORE_SCORING_GATHER_SUMS_H_
