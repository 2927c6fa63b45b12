// The branch and bound's queue (one heap per value) pops nodes in exactly the order one binary
// heap over all of them would: the exact search's results do not depend on which it uses.
#include "core/search/search_queue.h"

#include <limits>
#include <queue>
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

TEST(SearchQueueTest, PopsInTheOrderOfOneHeap) {
  std::mt19937_64 rng(5);
  SearchQueue reused;
  for (int round = 0; round < 20; ++round) {
    // Values around a first one that is not the largest, negative ones included, so the
    // buckets grow both ways; few distinct keys besides the value, so ties within a bucket
    // are decided by the rest of the key.
    std::uniform_int_distribution<int> value(-300 - 50 * round, 400 + 30 * round);
    std::uniform_int_distribution<int> small(0, 3), op(0, 2);
    SearchQueue fresh;
    // Every other round reuses the queue of the last (cleared, nodes left in it or not).
    SearchQueue& q = round % 2 == 0 ? fresh : reused;
    q.clear();
    std::priority_queue<PackedNode, std::vector<PackedNode>, PackedLess> ref;
    int pops = 0;
    for (int step = 0; step < 4000; ++step) {
      if (op(rng) < 2 || ref.empty()) {
        const PackedNode p = Node(value(rng), small(rng), small(rng));
        q.push(p);
        ref.push(p);
      } else {
        ASSERT_EQ(q.top().hi, ref.top().hi) << "round " << round << " step " << step;
        ASSERT_EQ(q.top().lo, ref.top().lo);
        EXPECT_EQ(SearchQueue::Value(q.top()), SearchQueue::Value(ref.top()));
        q.pop();
        ref.pop();
        ++pops;
      }
      ASSERT_EQ(q.size(), ref.size());
      ASSERT_EQ(q.empty(), ref.empty());
    }
    if (round % 4 == 1) continue;  // left full for the next clear().
    while (!ref.empty()) {
      ASSERT_EQ(q.top().hi, ref.top().hi);
      ASSERT_EQ(q.top().lo, ref.top().lo);
      q.pop();
      ref.pop();
    }
    EXPECT_TRUE(q.empty());
    EXPECT_GT(pops, 500);
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

TEST(SearchQueueTest, ValueIsWhatTheKeyHolds) {
  for (const int v : {-100000, -1, 0, 1, 7, 123456}) {
    EXPECT_EQ(SearchQueue::Value(Node(v, 0, 0)), v);
  }
  // A higher value is a larger key, whatever the rest holds.
  EXPECT_TRUE(PackedLess()(Node(-1, 0xFFFFFFFFu, ~0ull), Node(0, 0, 0)));
}

}  // namespace
}  // namespace hpose
