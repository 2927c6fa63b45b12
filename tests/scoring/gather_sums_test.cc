#include "core/scoring/gather_sums.h"

#include <algorithm>
#include <climits>
#include <cstdint>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace hpose {
namespace {

// A box of cells, four words a cell as in ColumnOccupancy's aligned layout, and random lookups
// around a base in its middle (negative offsets too), n not always a multiple of eight.
struct Lookups {
  std::vector<std::uint64_t> data;
  std::ptrdiff_t base = 0;
  std::ptrdiff_t row = 0;
  std::vector<std::int32_t> cxe, cy;
  std::vector<std::uint64_t> masks;
};

Lookups RandomLookups(std::mt19937_64* rng, int n) {
  Lookups l;
  const int nx = 40, ny = 36;
  l.row = nx * 4;
  l.data.resize(static_cast<size_t>(nx) * ny * 4);
  for (std::uint64_t& w : l.data) w = (*rng)() & (*rng)();
  l.base = (18 * nx + 20) * 4;
  std::uniform_int_distribution<int> dx(-8, 8), dy(-8, 8), entry(0, 3);
  for (int c = 0; c < n; ++c) {
    l.cxe.push_back(4 * dx(*rng) + entry(*rng));
    l.cy.push_back(dy(*rng));
    l.masks.push_back(c % 5 == 0 ? ~std::uint64_t{0} : (*rng)());
  }
  return l;
}

// The sum bit by bit, without popcount instructions.
int CountBits(const Lookups& l, std::ptrdiff_t shift) {
  int sum = 0;
  for (size_t c = 0; c < l.masks.size(); ++c) {
    const std::uint64_t w = l.masks[c] & l.data[l.base + shift + l.cy[c] * l.row + l.cxe[c]];
    for (int b = 0; b < 64; ++b) sum += static_cast<int>((w >> b) & 1);
  }
  return sum;
}

TEST(GatherSumsTest, TheScalarSumsCountTheMaskedBits) {
  std::mt19937_64 rng(5);
  for (int n = 0; n < 40; ++n) {
    const Lookups l = RandomLookups(&rng, n);
    ASSERT_EQ(GatherPopcountSumScalar(l.data.data(), l.base, l.row, l.cxe.data(), l.cy.data(),
                                      l.masks.data(), n),
              CountBits(l, 0))
        << "n " << n;
    const std::ptrdiff_t dx = 8, dy = 2 * l.row;
    int four[4];
    GatherPopcountSum4Scalar(l.data.data(), l.base, l.row, dx, dy, l.cxe.data(), l.cy.data(),
                             l.masks.data(), n, four);
    EXPECT_EQ(four[0], CountBits(l, 0));
    EXPECT_EQ(four[1], CountBits(l, dy));
    EXPECT_EQ(four[2], CountBits(l, dx));
    EXPECT_EQ(four[3], CountBits(l, dx + dy));
  }
}

TEST(GatherSumsTest, TheDispatchedSumsEqualTheScalarOnes) {
  if (!GatherPopcountSumVectorised()) {
    GTEST_SKIP() << "this CPU has no AVX-512 VPOPCNTDQ: the dispatched sums are the scalar ones";
  }
  std::mt19937_64 rng(9);
  int nonzero = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const int n = trial % 70;
    const Lookups l = RandomLookups(&rng, n);
    const int scalar = GatherPopcountSumScalar(l.data.data(), l.base, l.row, l.cxe.data(),
                                               l.cy.data(), l.masks.data(), n);
    ASSERT_EQ(GatherPopcountSum(l.data.data(), l.base, l.row, l.cxe.data(), l.cy.data(),
                                l.masks.data(), n),
              scalar)
        << "n " << n;
    nonzero += scalar > 0 ? 1 : 0;
    const std::ptrdiff_t dx = 4 * (1 + trial % 3), dy = (1 + trial % 2) * l.row;
    int fast[4], ref[4];
    GatherPopcountSum4(l.data.data(), l.base, l.row, dx, dy, l.cxe.data(), l.cy.data(),
                       l.masks.data(), n, fast);
    GatherPopcountSum4Scalar(l.data.data(), l.base, l.row, dx, dy, l.cxe.data(), l.cy.data(),
                             l.masks.data(), n, ref);
    for (int k = 0; k < 4; ++k) ASSERT_EQ(fast[k], ref[k]) << "n " << n << " block " << k;
  }
  EXPECT_GT(nonzero, 150);
}

struct Rows {
  int lo, hi;
};
constexpr Rows kAll = {INT_MIN, INT_MAX};

// The run sums' paths this CPU has (the scalar one always), and their names for messages.
std::vector<RunSumPath> AvailableRunSumPaths() {
  std::vector<RunSumPath> paths;
  for (const RunSumPath p : {RunSumPath::kScalar, RunSumPath::kAvx2, RunSumPath::kAvx512}) {
    if (RunSumPathAvailable(p)) paths.push_back(p);
  }
  return paths;
}
const char* Name(RunSumPath p) {
  return p == RunSumPath::kAvx512 ? "avx512" : p == RunSumPath::kAvx2 ? "avx2" : "scalar";
}

// The low `bytes` bytes of a word.
std::uint64_t LowBytes(std::uint64_t w, int bytes) {
  return bytes >= 8 ? w : w & ((std::uint64_t{1} << (8 * bytes)) - 1);
}

// A table as RunPopcountSum reads it (gather_sums.h), laid out by WriteRunTable.
std::vector<std::uint64_t> RunTable(const std::vector<CellRun>& runs,
                                    const std::vector<std::uint64_t>& masks, int bytes) {
  const int run_count = static_cast<int>(runs.size()), cells = static_cast<int>(masks.size());
  std::vector<std::uint64_t> words(RunTableWords(run_count, cells, bytes), ~0ull);
  WriteRunTable(runs.data(), run_count, masks.data(), cells, bytes, words.data());
  return words;
}

// A header gives back its run's cell, length and bytes; headers order as their rows do, the
// row limits take exactly the runs of their rows, no header is 0, and the sentinel is above
// every limit.
TEST(GatherSumsTest, RunHeadersKeepTheirRunAndOrderByRow) {
  const int cys[] = {-32767, -300, -1, 0, 1, 77, 32766};
  const int cxs[] = {kRunMinX, -4095, -5, -1, 0, 3, 4094, kRunMaxX};
  for (const int cy : cys) {
    for (const int cx : cxs) {
      for (int len = 1; len <= 8; ++len) {
        const RunHeaderWord h = RunHeader(cx, cy, len);
        ASSERT_EQ(RunHeaderX(h), cx);
        ASSERT_EQ(RunHeaderY(h), cy);
        ASSERT_EQ(RunHeaderLength(h), len);
        for (int bytes = 1; bytes <= 8; ++bytes) ASSERT_EQ(RunHeaderBytes(h, bytes), len * bytes);
        ASSERT_GT(h, 0u);
        ASSERT_LT(h, kRunSentinel);
        for (const int limit : {INT_MIN, -40000, -32768, cy - 1, cy, cy + 1, 40000, INT_MAX}) {
          ASSERT_EQ(h >= RunRowsFrom(limit), cy >= limit) << cy << " from " << limit;
          ASSERT_EQ(h <= RunRowsTo(limit), cy <= limit) << cy << " to " << limit;
        }
      }
    }
  }
  EXPECT_GT(kRunSentinel, RunRowsTo(INT_MAX));
  EXPECT_GE(kRunSentinel, RunRowsFrom(INT_MAX));
}

// Masks of every width are written and read back as they were, and a width holds the bytes up
// to the highest set bit.
TEST(GatherSumsTest, RunMasksOfEveryWidthReadBackAsWritten) {
  std::mt19937_64 rng(11);
  for (int bytes = 1; bytes <= 8; ++bytes) {
    std::vector<std::uint64_t> masks;
    for (int i = 0; i < 37; ++i) masks.push_back(LowBytes(rng(), bytes));
    masks.push_back(LowBytes(~0ull, bytes));  // every bit of the width.
    // Runs of 8 cells along row 0 (the last of 6), one per mask.
    std::vector<CellRun> runs;
    for (int c = 0; c < static_cast<int>(masks.size()); c += 8) {
      runs.push_back({c, 0, std::min(8, static_cast<int>(masks.size()) - c)});
    }
    const int n = static_cast<int>(runs.size());
    const std::vector<std::uint64_t> words = RunTable(runs, masks, bytes);
    // 64 bytes readable at every mask (a run's first, at most).
    ASSERT_GE(words.size() * 8, 4 * (n + 1) + (masks.size() - 1) * bytes + 64);
    for (int r = 0; r < n; ++r)
      ASSERT_EQ(RunHeaderAt(words.data(), r), RunHeader(8 * r, 0, runs[r].len));
    EXPECT_EQ(RunHeaderAt(words.data(), n), kRunSentinel);
    // Every byte after the masks is written, as 0 (RunTable starts from all ones).
    const auto* bytes_of = reinterpret_cast<const unsigned char*>(words.data());
    for (size_t b = 4 * (n + 1) + masks.size() * bytes; b < words.size() * 8; ++b) {
      ASSERT_EQ(bytes_of[b], 0) << "width " << bytes << " byte " << b;
    }
    for (size_t i = 0; i < masks.size(); ++i) {
      ASSERT_EQ(LoadRunMask(RunMasks(words.data(), n) + i * bytes, bytes), masks[i])
          << "width " << bytes << " mask " << i;
    }
    EXPECT_EQ(MaskBytes(std::uint64_t{1} << (8 * bytes - 1)), bytes);
    EXPECT_EQ(MaskBytes(LowBytes(~0ull, bytes)), bytes);
  }
  EXPECT_EQ(MaskBytes(0), 1);
  EXPECT_EQ(MaskBytes(1), 1);
  EXPECT_EQ(MaskBytes(std::uint64_t{1} << 36), 5);  // a body 37 cells tall.
}

// Runs of consecutive cells on a plane of one word per cell: random runs of 1..8 cells around
// the middle (negative offsets too), each summed by the dispatched and the scalar loop, both
// checked bit by bit.
TEST(GatherSumsTest, RunSumsCountTheMaskedBitsOfEveryRun) {
  std::mt19937_64 rng(13);
  const int nx = 50, ny = 40;
  std::vector<std::uint64_t> plane(static_cast<size_t>(nx) * ny);
  for (std::uint64_t& w : plane) w = rng() & rng();
  const std::ptrdiff_t base = 20 * nx + 20;
  std::uniform_int_distribution<int> off(-10, 10), len(1, 8);
  int nonzero = 0;
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<std::int32_t> run_cx, run_cy, run_len;
    std::vector<CellRun> headers;
    std::vector<std::uint64_t> masks;
    const int runs = trial % 25;
    const int bytes = 1 + trial % 8;  // every mask width.
    for (int r = 0; r < runs; ++r) {
      run_cx.push_back(off(rng));
      run_cy.push_back(off(rng));
      run_len.push_back(len(rng));
      headers.push_back({run_cx.back(), run_cy.back(), run_len.back()});
      for (int i = 0; i < run_len.back(); ++i) {
        masks.push_back(LowBytes(r % 4 == 0 ? ~0ull : rng(), bytes));
      }
    }
    // words: the runs as RunPopcountSum reads them.
    const std::vector<std::uint64_t> words = RunTable(headers, masks, bytes);
    const std::ptrdiff_t dx = 1 + trial % 4, dy = (1 + trial % 3) * nx;
    const std::ptrdiff_t shifts[4] = {0, dy, dx, dx + dy};
    int bits[4] = {0, 0, 0, 0};
    for (int q = 0; q < 4; ++q) {
      size_t k = 0;
      for (int r = 0; r < runs; ++r) {
        for (int i = 0; i < run_len[r]; ++i, ++k) {
          const std::uint64_t w =
              masks[k] & plane[base + shifts[q] + run_cy[r] * nx + run_cx[r] + i];
          for (int b = 0; b < 64; ++b) bits[q] += static_cast<int>((w >> b) & 1);
        }
      }
    }
    ASSERT_EQ(
        RunPopcountSumScalar(plane.data(), base, nx, words.data(), runs, bytes, kAll.lo, kAll.hi),
        bits[0]);
    ASSERT_EQ(RunPopcountSum(plane.data(), base, nx, words.data(), runs, bytes, kAll.lo, kAll.hi),
              bits[0])
        << "runs " << runs << " width " << bytes;
    int fast[4], ref[4];
    RunPopcountSum4(plane.data(), base, nx, dx, dy, words.data(), runs, bytes, kAll.lo, kAll.hi,
                    fast);
    RunPopcountSum4Scalar(plane.data(), base, nx, dx, dy, words.data(), runs, bytes, kAll.lo,
                          kAll.hi, ref);
    for (int q = 0; q < 4; ++q) {
      ASSERT_EQ(ref[q], bits[q]) << "block " << q << " width " << bytes;
      ASSERT_EQ(fast[q], bits[q]) << "block " << q << " width " << bytes;
    }
    for (const RunSumPath path : AvailableRunSumPaths()) {
      ASSERT_EQ(RunPopcountSumOn(path, plane.data(), base, nx, words.data(), runs, bytes, kAll.lo,
                                 kAll.hi),
                bits[0])
          << Name(path) << " runs " << runs << " width " << bytes;
      int on[4];
      RunPopcountSum4On(path, plane.data(), base, nx, dx, dy, words.data(), runs, bytes, kAll.lo,
                        kAll.hi, on);
      for (int q = 0; q < 4; ++q) {
        ASSERT_EQ(on[q], bits[q]) << Name(path) << " block " << q << " width " << bytes;
      }
    }
    nonzero += bits[0] > 0 ? 1 : 0;
  }
  EXPECT_GT(nonzero, 150);
}

// A plane that is zero outside some rows (a small cluster): runs in CellGroups' order (rows
// ascending) summed with those rows as limits equal the sums over every run, for one block and
// for four (whose second row of blocks reads d rows further down).
TEST(GatherSumsTest, RunSumsSkipOnlyRowsOfZeros) {
  std::mt19937_64 rng(17);
  const int nx = 50, ny = 60;
  const std::ptrdiff_t base = 25 * nx + 20;
  std::uniform_int_distribution<int> off(-12, 12), len(1, 8);
  int skipped_nonzero = 0;
  for (int trial = 0; trial < 200; ++trial) {
    // Rows [lo, hi] of the plane (absolute) hold voxels; the others are zero.
    const int lo = 14 + trial % 9, hi = lo + trial % 13;
    std::vector<std::uint64_t> plane(static_cast<size_t>(nx) * ny, 0);
    for (int y = lo; y <= hi; ++y) {
      for (int x = 0; x < nx; ++x) plane[static_cast<size_t>(y) * nx + x] = rng() & rng();
    }
    // Runs sorted by (cy, cx), each once.
    std::vector<std::pair<int, int>> starts;
    for (int r = 0; r < 30; ++r) starts.emplace_back(off(rng), off(rng));
    std::sort(starts.begin(), starts.end());
    std::vector<CellRun> headers;
    std::vector<std::uint64_t> masks;
    const int bytes = 8 - trial % 8;
    for (const auto& [cy, cx] : starts) {
      const int n = len(rng);
      headers.push_back({cx, cy, n});
      for (int i = 0; i < n; ++i) masks.push_back(LowBytes(rng(), bytes));
    }
    const int runs = static_cast<int>(headers.size());
    const std::vector<std::uint64_t> words = RunTable(headers, masks, bytes);
    const int row0 = static_cast<int>(base / nx);  // the plane row of cy = 0.
    const int d = 1 + trial % 3;
    const std::ptrdiff_t dx = d, dy = d * nx;
    const int all =
        RunPopcountSumScalar(plane.data(), base, nx, words.data(), runs, bytes, kAll.lo, kAll.hi);
    ASSERT_EQ(
        RunPopcountSum(plane.data(), base, nx, words.data(), runs, bytes, lo - row0, hi - row0),
        all);
    ASSERT_EQ(RunPopcountSumScalar(plane.data(), base, nx, words.data(), runs, bytes, lo - row0,
                                   hi - row0),
              all);
    int full[4], limited[4], limited_ref[4];
    RunPopcountSum4Scalar(plane.data(), base, nx, dx, dy, words.data(), runs, bytes, kAll.lo,
                          kAll.hi, full);
    RunPopcountSum4(plane.data(), base, nx, dx, dy, words.data(), runs, bytes, lo - row0 - d,
                    hi - row0, limited);
    RunPopcountSum4Scalar(plane.data(), base, nx, dx, dy, words.data(), runs, bytes, lo - row0 - d,
                          hi - row0, limited_ref);
    for (int q = 0; q < 4; ++q) {
      ASSERT_EQ(limited[q], full[q]) << "block " << q;
      ASSERT_EQ(limited_ref[q], full[q]) << "block " << q;
    }
    for (const RunSumPath path : AvailableRunSumPaths()) {
      ASSERT_EQ(RunPopcountSumOn(path, plane.data(), base, nx, words.data(), runs, bytes, lo - row0,
                                 hi - row0),
                all)
          << Name(path);
      int on[4];
      RunPopcountSum4On(path, plane.data(), base, nx, dx, dy, words.data(), runs, bytes,
                        lo - row0 - d, hi - row0, on);
      for (int q = 0; q < 4; ++q) ASSERT_EQ(on[q], full[q]) << Name(path) << " block " << q;
    }
    // A limit one row too tight loses the sum of a non-zero row whenever a run reads it.
    const int tight =
        RunPopcountSum(plane.data(), base, nx, words.data(), runs, bytes, lo - row0 + 1, hi - row0);
    skipped_nonzero += tight < all ? 1 : 0;
  }
  EXPECT_GT(skipped_nonzero, 20);  // the limits do leave runs out.
}

// This CPU's fastest path is the one the dispatched sums take; the scalar one is always there,
// and a CPU with AVX-512's run sums has AVX2's too.
TEST(GatherSumsTest, TheFastestRunSumPathIsAvailable) {
  EXPECT_TRUE(RunSumPathAvailable(RunSumPath::kScalar));
  EXPECT_TRUE(RunSumPathAvailable(FastestRunSumPath()));
  if (RunSumPathAvailable(RunSumPath::kAvx512)) {
    EXPECT_TRUE(RunSumPathAvailable(RunSumPath::kAvx2));
    EXPECT_EQ(FastestRunSumPath(), RunSumPath::kAvx512);
  } else if (RunSumPathAvailable(RunSumPath::kAvx2)) {
    EXPECT_EQ(FastestRunSumPath(), RunSumPath::kAvx2);
  } else {
    EXPECT_EQ(FastestRunSumPath(), RunSumPath::kScalar);
  }
}

}  // namespace
}  // namespace hpose
