#include "core/scoring/zeroed_words.h"

#include <algorithm>
#include <cstdint>
#include <random>
#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

namespace hpose {
namespace {

bool AllZero(const ZeroedWords& w) {
  return std::all_of(w.data(), w.data() + w.size(), [](std::uint64_t v) { return v == 0; });
}

// An array written in its declared rectangle and given back: the next array of that size gets
// the same buffer, all zero again.
TEST(ZeroedWordsTest, ABufferGivenBackIsZeroWhenTakenAgain) {
  const std::size_t nx = 40, ny = 30, n = nx * ny * 4;
  const std::uint64_t* first = nullptr;
  {
    ZeroedWords w(n);
    ASSERT_EQ(w.size(), n);
    EXPECT_TRUE(AllZero(w));
    first = w.data();
    // Cells [5, 12] x [7, 20], four words a cell.
    w.MarkWritten((7 * nx + 5) * 4, 8 * 4, nx * 4, 14);
    for (std::size_t y = 7; y <= 20; ++y) {
      for (std::size_t x = 5; x <= 12; ++x) {
        for (int e = 0; e < 4; ++e) w[(y * nx + x) * 4 + e] = ~std::uint64_t{0} - e;
      }
    }
  }
  ZeroedWords again(n);
  EXPECT_EQ(again.data(), first) << "the pool should hand the same buffer back";
  EXPECT_TRUE(AllZero(again));
}

// Two rectangles declared: everything from the first's first word to the second's last is
// zeroed, whatever was written in either.
TEST(ZeroedWordsTest, TwoRectanglesAreBothZeroedAgain) {
  const std::size_t n = 9000;
  const std::uint64_t* first = nullptr;
  {
    ZeroedWords w(n);
    first = w.data();
    w.MarkWritten(8000, 10, 100, 5);  // 8000..8409
    w.MarkWritten(100, 3, 50, 4);     // 100..252
    for (std::size_t r = 0; r < 5; ++r) w[8000 + r * 100 + 9] = 1;
    for (std::size_t r = 0; r < 4; ++r) w[100 + r * 50] = 2;
  }
  ZeroedWords again(n);
  EXPECT_EQ(again.data(), first);
  EXPECT_TRUE(AllZero(again));
}

// A moved array gives its buffer back once, from where it went; a moved-from one holds none.
TEST(ZeroedWordsTest, MovesHandOverTheBuffer) {
  const std::size_t before = ZeroedWords::PooledBuffers();
  const std::size_t n = 7777;
  std::uint64_t* p = nullptr;
  {
    ZeroedWords a(n);
    p = a.data();
    a.MarkAllWritten();
    a[n - 1] = 9;
    ZeroedWords b(std::move(a));
    EXPECT_EQ(a.data(), nullptr);  // NOLINT(bugprone-use-after-move): what a move leaves.
    EXPECT_EQ(a.size(), 0u);       // NOLINT(bugprone-use-after-move)
    EXPECT_EQ(b.data(), p);
    ZeroedWords c;
    c = std::move(b);
    EXPECT_EQ(c.data(), p);
    EXPECT_EQ(c[n - 1], 9u);
    EXPECT_LE(ZeroedWords::PooledBuffers(), before);  // taken, not yet given back.
  }
  EXPECT_LE(ZeroedWords::PooledBuffers(), before + 1);
  ZeroedWords again(n);
  EXPECT_EQ(again.data(), p);
  EXPECT_TRUE(AllZero(again));
}

// Arrays larger than the pool keeps are freed, not kept; an empty array holds no buffer.
TEST(ZeroedWordsTest, ThePoolKeepsNoMoreThanItsLimit) {
  const std::size_t before = ZeroedWords::PooledBuffers();
  { ZeroedWords huge(ZeroedWords::kPoolBytes / sizeof(std::uint64_t) + 1); }
  EXPECT_EQ(ZeroedWords::PooledBuffers(), before);
  ZeroedWords empty(0);
  EXPECT_EQ(empty.data(), nullptr);
  EXPECT_EQ(empty.size(), 0u);
}

// Threads taking, writing and giving back arrays of many sizes at once: every array is all
// zero when taken.
TEST(ZeroedWordsTest, ThreadsShareThePool) {
  std::vector<std::thread> threads;
  std::vector<int> dirty(4, 0);
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([t, &dirty] {
      std::mt19937 rng(100 + t);
      std::uniform_int_distribution<std::size_t> size(1, 20000);
      for (int k = 0; k < 300; ++k) {
        ZeroedWords w(size(rng));
        if (!AllZero(w)) ++dirty[t];
        const std::size_t rows = std::min<std::size_t>(w.size(), 7);
        const std::size_t stride = w.size() / rows;
        const std::size_t width = std::max<std::size_t>(1, stride / 2);
        w.MarkWritten(0, width, stride, rows);
        for (std::size_t r = 0; r < rows; ++r) {
          for (std::size_t i = 0; i < width; ++i) w[r * stride + i] = k + 1;
        }
      }
    });
  }
  for (std::thread& th : threads) th.join();
  for (int t = 0; t < 4; ++t) EXPECT_EQ(dirty[t], 0) << "thread " << t;
}

}  // namespace
}  // namespace hpose
