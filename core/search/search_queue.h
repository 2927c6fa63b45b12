#ifndef HPOSE_CORE_SEARCH_SEARCH_QUEUE_H_
#define HPOSE_CORE_SEARCH_SEARCH_QUEUE_H_

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace hpose {

// The queue's order: highest value first; among equal values coarser nodes first (bounds
// before exact poses), then lower itheta, a, b, tlevel: a strict order, so results never depend
// on the heap's layout. Coarser first, every block bounded at the optimum's value is split
// before a pose of that value leaves the queue: the optimum found is the one with the lowest
// (itheta, a, b) among the poses of the highest value, whatever the bounds (before, finer
// first, which pose of equal value came out depended on how the blocks above it were bounded).
// Nodes are queued packed into 128 bits whose unsigned order is that order (16 bytes instead of 28,
// one or two integer compares per heap step). The value sits in the top 32 bits of `hi`, biased by
// 2^31.
struct PackedNode {
  std::uint64_t hi;  // value (biased) | fine | 0xFFFF - itheta.
  std::uint64_t lo;  // 2^24-1 - (a - a0) | 2^24-1 - (b - b0) | 7 - tlevel | level | loose.
};

struct PackedLess {
  bool operator()(const PackedNode& x, const PackedNode& y) const {
    return x.hi != y.hi ? x.hi < y.hi : x.lo < y.lo;
  }
};

// The queue of nodes: one binary heap per value (a node's value is a small integer), so that a
// push or a pop sifts through the nodes of one value only. Pops in exactly the order of one heap
// over all the nodes (PackedLess).
class SearchQueue {
 public:
  bool empty() const { return size_ == 0; }
  size_t bucket_count() const { return buckets_.size(); }
  size_t size() const { return size_; }
  const PackedNode& top() const { return buckets_[top_].front(); }
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
      buckets_.insert(buckets_.begin(), static_cast<size_t>(extra), std::vector<PackedNode>());
      base_ -= extra;
      top_ += extra;
    }
    const size_t k = static_cast<size_t>(v - base_);
    if (k >= buckets_.size()) buckets_.resize(std::max(k + 1, 2 * buckets_.size()));
    std::vector<PackedNode>& b = buckets_[k];
    b.push_back(p);
    std::push_heap(b.begin(), b.end(), PackedLess());
    if (size_ == 0 || static_cast<int>(k) > top_) top_ = static_cast<int>(k);
    ++size_;
  }
  void pop() {
    std::vector<PackedNode>& b = buckets_[top_];
    std::pop_heap(b.begin(), b.end(), PackedLess());
    b.pop_back();
    --size_;
    if (size_ == 0) return;
    while (buckets_[top_].empty()) --top_;
  }

  // Empties the queue, keeping its buckets' memory for the next search (buckets for about as
  // many values as the widest search so far spanned, a few times over).
  void clear() {
    for (std::vector<PackedNode>& b : buckets_) b.clear();
    size_ = 0;
    top_ = 0;
    fresh_ = true;
  }

  static int Value(const PackedNode& p) {
    return static_cast<int>(static_cast<std::uint32_t>(p.hi >> 32) ^ 0x80000000u);
  }

 private:
  std::vector<std::vector<PackedNode>> buckets_;  // bucket k: nodes of value base_ + k.
  int base_ = 0;
  int top_ = 0;  // the highest non-empty bucket (when size_ > 0).
  size_t size_ = 0;
  bool fresh_ = true;  // no node pushed since construction or clear(): base_ is still free.
};

}  // namespace hpose

#endif  // HPOSE_CORE_SEARCH_SEARCH_QUEUE_H_
