// The branch and bound's queue (a stack of blocks and a heap of poses per value) pops the
// highest value first; within a value the block pushed last, else the pose a binary heap would
// (PackedLess). The exact search's optimum depends only on the poses' order (tests in
// exact_search_test.cc and exact_search_bounds_test.cc compare it with brute force).
#include "core/search/search_queue.h"

#include <algorithm>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace hpose {
namespace {

PackedNode Node(int value, std::uint64_t rest_hi, std::uint64_t lo) {
  PackedNode p;
  p.hi = (static_cast<std::uint64_t>(static_cast<std::uint32_t>(value) ^ 0x80000000u) << 32) |
         (rest_hi & 0xFFFFFFFFu);
  p.lo = lo;
  return p;
}

// A node of the given value: a pose when `fine` is 0, else a block.
PackedNode Node(int value, int fine, std::uint64_t rest_hi, std::uint64_t lo) {
  return Node(
      value, (static_cast<std::uint64_t>(fine) << PackedNode::kFineShift) | (rest_hi & 0xFFFF), lo);
}

// What the queue must pop, by looking at every queued node (in the order pushed): the highest
// value; of it the last block pushed, else the largest pose by PackedLess.
size_t Expected(const std::vector<PackedNode>& pushed) {
  int best_value = std::numeric_limits<int>::min();
  for (const PackedNode& p : pushed) best_value = std::max(best_value, SearchQueue::Value(p));
  constexpr size_t kNone = std::numeric_limits<size_t>::max();
  size_t last_block = kNone, best_pose = kNone;
  for (size_t i = 0; i < pushed.size(); ++i) {
    const PackedNode& p = pushed[i];
    if (SearchQueue::Value(p) != best_value) continue;
    if (!SearchQueue::IsPose(p)) {
      last_block = i;
    } else if (best_pose == kNone || PackedLess()(pushed[best_pose], p)) {
      best_pose = i;
    }
  }
  return last_block != kNone ? last_block : best_pose;
}

TEST(SearchQueueTest, PopsBlocksLastInFirstOutThenPosesInHeapOrder) {
  std::mt19937_64 rng(5);
  SearchQueue reused;
  for (int round = 0; round < 20; ++round) {
    // Values around a first one that is not the largest, negative ones included, so the
    // buckets grow both ways; few distinct keys besides the value, so ties within a bucket
    // are decided by the rest of the key; blocks and poses mixed.
    std::uniform_int_distribution<int> value(-300 - 50 * round, 400 + 30 * round);
    std::uniform_int_distribution<int> small(0, 3), op(0, 2), fine(0, 2);
    SearchQueue fresh;
    // Every other round reuses the queue of the last (cleared, nodes left in it or not).
    SearchQueue& q = round % 2 == 0 ? fresh : reused;
    q.clear();
    std::vector<PackedNode> ref;  // in the order pushed.
    int pops = 0, block_pops = 0, pose_pops = 0;
    for (int step = 0; step < 2000; ++step) {
      if (op(rng) < 2 || ref.empty()) {
        const PackedNode p = Node(value(rng), fine(rng), small(rng), small(rng));
        q.push(p);
        ref.push_back(p);
      } else {
        const size_t e = Expected(ref);
        ASSERT_EQ(q.top().hi, ref[e].hi) << "round " << round << " step " << step;
        ASSERT_EQ(q.top().lo, ref[e].lo);
        ASSERT_EQ(q.top_value(), SearchQueue::Value(ref[e]));
        (SearchQueue::IsPose(ref[e]) ? pose_pops : block_pops) += 1;
        q.pop();
        ref.erase(ref.begin() + static_cast<std::ptrdiff_t>(e));
        ++pops;
      }
      ASSERT_EQ(q.size(), ref.size());
      ASSERT_EQ(q.empty(), ref.empty());
    }
    if (round % 4 == 1) continue;  // left full for the next clear().
    while (!ref.empty()) {
      const size_t e = Expected(ref);
      ASSERT_EQ(q.top().hi, ref[e].hi);
      ASSERT_EQ(q.top().lo, ref[e].lo);
      q.pop();
      ref.erase(ref.begin() + static_cast<std::ptrdiff_t>(e));
    }
    EXPECT_TRUE(q.empty());
    EXPECT_GT(pops, 300);
    EXPECT_GT(block_pops, 50);
    EXPECT_GT(pose_pops, 50);
  }
}

// A queue cleared and reused search after search keeps its memory, but not more of it than the
// values of one search need, wherever they lie.
TEST(SearchQueueTest, ReuseKeepsTheBucketsBounded) {
  std::mt19937_64 rng(9);
  std::uniform_int_distribution<int> offset(-100000, 100000), value(0, 1000);
  SearchQueue q;
  for (int search = 0; search < 300; ++search) {
    q.clear();
    const int base = offset(rng);
    for (int i = 0; i < 200; ++i) q.push(Node(base + value(rng), 0, i));
    int last = std::numeric_limits<int>::max();
    for (int i = 0; i < 100; ++i) {
      ASSERT_LE(SearchQueue::Value(q.top()), last);
      last = SearchQueue::Value(q.top());
      q.pop();
    }
  }
  // One bucket per value; the first node's value may lie anywhere in the range (three
  // quarters of the buckets are kept below it), and growing doubles: at most 8 ranges.
  EXPECT_LE(q.bucket_count(), 8u * 1001u);
}

// The blocks of every value share one store: reused search after search, with values that fall
// anywhere, it holds as many as were ever queued at once (a vector's doubling over), not as many
// as each bucket ever held.
TEST(SearchQueueTest, StoreHoldsTheMostBlocksQueuedAtOnce) {
  std::mt19937_64 rng(3);
  std::uniform_int_distribution<int> offset(-5000, 5000), value(0, 300), fine(1, 20);
  SearchQueue q;
  size_t most = 0;
  for (int search = 0; search < 200; ++search) {
    q.clear();
    const int base = offset(rng);
    const int count = 50 + search % 150;
    for (int i = 0; i < count; ++i) {
      q.push(Node(base + value(rng), fine(rng), 0, static_cast<std::uint64_t>(i)));
      if (i % 3 != 0) q.pop();  // searches pop as they go: most blocks leave soon.
      most = std::max(most, q.size());
    }
  }
  EXPECT_GE(q.slot_capacity(), most);
  EXPECT_LE(q.slot_capacity(), 2 * most);
}

// Reserve makes room for that many blocks at once (pushing them takes no new memory) and leaves
// the queue empty, its order unchanged.
TEST(SearchQueueTest, ReserveMakesRoomAndEmptiesTheQueue) {
  SearchQueue q;
  q.push(Node(7, 3, 0, 1));
  q.Reserve(1000);
  EXPECT_TRUE(q.empty());
  EXPECT_GE(q.slot_capacity(), 1000u);
  const size_t capacity = q.slot_capacity();
  for (int i = 0; i < 1000; ++i) q.push(Node(i % 37, 2, 0, static_cast<std::uint64_t>(i)));
  EXPECT_EQ(q.slot_capacity(), capacity);
  // The last block pushed of the highest value (36: i = 36, 73, ..., 998) leaves first.
  EXPECT_EQ(SearchQueue::Value(q.top()), 36);
  EXPECT_EQ(q.top().lo, 998u);
  q.Reserve(10);  // never less than it has.
  EXPECT_TRUE(q.empty());
  EXPECT_EQ(q.slot_capacity(), capacity);
}

TEST(SearchQueueTest, ValueIsWhatTheKeyHolds) {
  for (const int v : {-100000, -1, 0, 1, 7, 123456}) {
    EXPECT_EQ(SearchQueue::Value(Node(v, 0, 0)), v);
  }
  // A higher value is a larger key, whatever the rest holds.
  EXPECT_TRUE(PackedLess()(Node(-1, 0xFFFFFFFFu, ~0ull), Node(0, 0, 0)));
}

}  // namespace
}  // namespace hpose
