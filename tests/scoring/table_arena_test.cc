#include "core/scoring/table_arena.h"

#include <algorithm>
#include <cstdint>
#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

namespace hpose {
namespace {

bool Overlap(const std::pair<std::uintptr_t, std::size_t>& a,
             const std::pair<std::uintptr_t, std::size_t>& b) {
  return a.first < b.first + b.second && b.first < a.first + a.second;
}

// Allocations are cache-line aligned, disjoint and writable, from small ones to one larger than
// any region, and the regions grow as they fill.
TEST(TableArenaTest, AllocationsAreAlignedDisjointAndWritable) {
  TableArena arena;
  EXPECT_EQ(arena.mapped_bytes(), 0u);
  std::vector<std::pair<std::uintptr_t, std::size_t>> blocks;
  const std::size_t sizes[] = {1, 8, 63, 64, 65, 4096, 100000, std::size_t{40} << 20, 24};
  for (int round = 0; round < 3; ++round) {
    for (const std::size_t bytes : sizes) {
      auto* p = static_cast<unsigned char*>(arena.Allocate(bytes));
      ASSERT_NE(p, nullptr);
      EXPECT_EQ(reinterpret_cast<std::uintptr_t>(p) % 64, 0u) << bytes << " bytes";
      std::fill(p, p + bytes, static_cast<unsigned char>(bytes & 0xFF));
      EXPECT_EQ(p[0], static_cast<unsigned char>(bytes & 0xFF));
      EXPECT_EQ(p[bytes - 1], static_cast<unsigned char>(bytes & 0xFF));
      blocks.emplace_back(reinterpret_cast<std::uintptr_t>(p), bytes);
    }
  }
  for (size_t i = 0; i < blocks.size(); ++i) {
    for (size_t j = i + 1; j < blocks.size(); ++j) {
      EXPECT_FALSE(Overlap(blocks[i], blocks[j])) << "blocks " << i << " and " << j;
    }
  }
  // Three 40 MB blocks at least, each in a region of its own size or more.
  EXPECT_GE(arena.mapped_bytes(), 3 * (std::size_t{40} << 20));
}

// Threads that make tables at once (searches make them on first use) get disjoint memory.
TEST(TableArenaTest, ThreadsAllocateDisjointBlocks) {
  TableArena arena;
  constexpr int kThreads = 4, kEach = 2000;
  std::vector<std::vector<std::uintptr_t>> got(kThreads);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      for (int i = 0; i < kEach; ++i) {
        auto* p = static_cast<std::uint64_t*>(arena.Allocate(64 * (1 + i % 5)));
        p[0] = static_cast<std::uint64_t>(t) << 32 | static_cast<std::uint64_t>(i);
        got[t].push_back(reinterpret_cast<std::uintptr_t>(p));
      }
    });
  }
  for (std::thread& th : threads) th.join();
  std::vector<std::pair<std::uintptr_t, std::size_t>> all;
  for (int t = 0; t < kThreads; ++t) {
    for (int i = 0; i < kEach; ++i) {
      // Nobody else wrote over this thread's first word.
      EXPECT_EQ(*reinterpret_cast<const std::uint64_t*>(got[t][i]),
                static_cast<std::uint64_t>(t) << 32 | static_cast<std::uint64_t>(i));
      all.emplace_back(got[t][i], 64 * (1 + i % 5));
    }
  }
  std::sort(all.begin(), all.end());
  for (size_t k = 1; k < all.size(); ++k) EXPECT_FALSE(Overlap(all[k - 1], all[k]));
}

// A container keeps its arena through copies, moves and swaps; one without an arena uses the
// heap and can be mixed with them by value.
TEST(TableArenaTest, AllocatorTravelsWithItsContainer) {
  TableArena arena, other;
  TableWords a{TableAllocator<std::uint64_t>(&arena)};
  a.assign({1, 2, 3, 4, 5});
  EXPECT_EQ(a.get_allocator().arena(), &arena);
  TableWords copy = a;
  EXPECT_EQ(copy.get_allocator().arena(), &arena);
  EXPECT_EQ(copy, a);
  TableWords assigned{TableAllocator<std::uint64_t>(&other)};
  assigned = a;  // copy assignment takes a's arena.
  EXPECT_EQ(assigned.get_allocator().arena(), &arena);
  TableWords moved = std::move(copy);
  EXPECT_EQ(moved.get_allocator().arena(), &arena);
  EXPECT_EQ(moved, a);
  TableWords heap;  // no arena: the heap.
  EXPECT_EQ(heap.get_allocator().arena(), nullptr);
  heap = a;
  EXPECT_EQ(heap, a);
  heap.push_back(6);
  EXPECT_EQ(heap.size(), 6u);
  TableWords plain(3, 7);
  plain.swap(heap);
  EXPECT_EQ(plain.size(), 6u);
  EXPECT_EQ(heap, TableWords(3, 7));
  // The arena's memory stays valid while the arena lives, whatever the containers did.
  EXPECT_EQ(a[4], 5u);
}

}  // namespace
}  // namespace hpose
