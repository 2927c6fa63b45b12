#ifndef HPOSE_CORE_SEARCH_SEARCH_QUEUE_H_
#define HPOSE_CORE_SEARCH_SEARCH_QUEUE_H_

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace hpose {

// The queue's order: highest value first; among equal values blocks (bounds) before exact poses,
// and exact poses by lower itheta, a, b. Blocks of one value leave in any order (the queue takes
// the last one pushed): every block of the highest value is split before a pose of that value
// leaves, whatever their order, so the optimum found is the one with the lowest (itheta, a, b)
// among the poses of the highest value, whatever the bounds, and the blocks split are the same
// (before, finer first, which pose of equal value came out depended on how the blocks above it
// were bounded). Nodes are queued packed into 128 bits whose unsigned order is that of the
// poses (16 bytes instead of 28, one or two integer compares per heap step). The value sits in
// the top 32 bits of `hi`, biased by 2^31; a pose's `fine` field (bits 16-20 of `hi`) is 0.
struct PackedNode {
  std::uint64_t hi;  // value (biased) | fine | 0xFFFF - itheta.
  std::uint64_t lo;  // 2^24-1 - (a - a0) | 2^24-1 - (b - b0) | 7 - tlevel | level | loose.
  // Where `fine` (tlevel + level: 0 for an exact pose) sits in `hi`.
  static constexpr int kFineShift = 16;
  static constexpr std::uint64_t kFineMask = 0x1F;
};

struct PackedLess {
  bool operator()(const PackedNode& x, const PackedNode& y) const {
    return x.hi != y.hi ? x.hi < y.hi : x.lo < y.lo;
  }
};

// The queue of nodes: one bucket per value (a node's value is a small integer), each a stack of
// blocks and a binary heap of poses, so that a block's push or pop touches the top of one stack
// (the one the search just used, mostly) and a pose's sifts through the poses of one value only.
// The blocks of every bucket live in one store of slots, each stack linked through its slots and
// the free slots in a stack of their own: a push takes the slot the last pop freed (still in the
// caches), and the store holds as many blocks as the queue has held at once, whatever their
// values. (Stacks of their own per bucket grew, search after search, to the largest any search
// put at that bucket's offset: new memory, page faults included, whenever a search's values
// fell where earlier ones had put few blocks.)
class SearchQueue {
 public:
  bool empty() const { return size_ == 0; }
  size_t bucket_count() const { return buckets_.size(); }
  size_t size() const { return size_; }
  // Slots the store has made so far (the most blocks held at once, or what Reserve asked for).
  size_t slot_capacity() const { return slots_.capacity(); }
  const PackedNode& top() const {
    const Bucket& b = buckets_[top_];
    return b.head != kNone ? slots_[b.head].node : b.poses.front();
  }
  // Value(top()), from the bucket's place alone: the top node itself may be out of the caches.
  int top_value() const { return base_ + top_; }
  void push(const PackedNode& p) {
    const int v = Value(p);
    if (fresh_) {  // the first node: buckets around its value (values fall as a search goes).
      if (buckets_.size() < 64) buckets_.resize(64);
      base_ = v - static_cast<int>(buckets_.size()) * 3 / 4;
      top_ = 0;
      fresh_ = false;
    }
    if (v < base_) {  // grow downwards: shift the buckets up.
      const int extra = std::max(base_ - v, static_cast<int>(buckets_.size()) / 2);
      buckets_.insert(buckets_.begin(), static_cast<size_t>(extra), Bucket());
      base_ -= extra;
      top_ += extra;
    }
    const size_t k = static_cast<size_t>(v - base_);
    if (k >= buckets_.size()) buckets_.resize(std::max(k + 1, 2 * buckets_.size()));
    Bucket& b = buckets_[k];
    if (IsPose(p)) {
      b.poses.push_back(p);
      std::push_heap(b.poses.begin(), b.poses.end(), PackedLess());
    } else {
      const Slot pushed{p, b.head};
      if (free_ != kNone) {
        b.head = free_;
        free_ = slots_[free_].next;
        slots_[b.head] = pushed;
      } else {
        b.head = static_cast<std::int32_t>(slots_.size());
        slots_.push_back(pushed);
      }
    }
    if (size_ == 0 || static_cast<int>(k) > top_) top_ = static_cast<int>(k);
    ++size_;
  }
  void pop() {
    Bucket& b = buckets_[top_];
    if (b.head != kNone) {
      const std::int32_t slot = b.head;
      b.head = slots_[slot].next;
      slots_[slot].next = free_;
      free_ = slot;
    } else {
      std::pop_heap(b.poses.begin(), b.poses.end(), PackedLess());
      b.poses.pop_back();
    }
    --size_;
    if (size_ == 0) return;
    while (buckets_[top_].empty()) --top_;
    // The next top leaves soon, unless a node pushed meanwhile goes before it.
    const std::int32_t next = buckets_[top_].head;
    if (next != kNone) __builtin_prefetch(&slots_[next]);
  }

  // Empties the queue, keeping its memory for the next search (the store, and buckets for about
  // as many values as the widest search so far spanned, a few times over).
  void clear() {
    for (Bucket& b : buckets_) {
      b.head = kNone;
      b.poses.clear();
    }
    slots_.clear();
    free_ = kNone;
    size_ = 0;
    top_ = 0;
    fresh_ = true;
  }
  // Makes (and writes, so that its pages are the process's) room for `blocks` blocks held at
  // once; empties the queue.
  void Reserve(size_t blocks) {
    clear();
    slots_.resize(std::max(blocks, slots_.size()));
    slots_.clear();
  }

  static int Value(const PackedNode& p) {
    return static_cast<int>(static_cast<std::uint32_t>(p.hi >> 32) ^ 0x80000000u);
  }
  // An exact pose (a single theta and translation), not a block.
  static bool IsPose(const PackedNode& p) {
    return ((p.hi >> PackedNode::kFineShift) & PackedNode::kFineMask) == 0;
  }

 private:
  static constexpr std::int32_t kNone = -1;
  struct Slot {
    PackedNode node;
    std::int32_t next = kNone;  // the slot below in its bucket's stack, or in the free stack.
  };
  struct Bucket {
    std::int32_t head = kNone;      // the block pushed last (the first to leave).
    std::vector<PackedNode> poses;  // a heap (PackedLess).
    bool empty() const { return head == kNone && poses.empty(); }
  };
  std::vector<Bucket> buckets_;  // bucket k: nodes of value base_ + k.
  std::vector<Slot> slots_;      // the blocks of every bucket, and free slots.
  std::int32_t free_ = kNone;    // the free slot freed last.
  int base_ = 0;
  int top_ = 0;  // the highest non-empty bucket (when size_ > 0).
  size_t size_ = 0;
  bool fresh_ = true;  // no node pushed since construction or clear(): base_ is still free.
};

}  // namespace hpose

#endif  // HPOSE_CORE_SEARCH_SEARCH_QUEUE_H_
