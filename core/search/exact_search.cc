#include "core/search/exact_search.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <vector>

#include "core/scoring/column_occupancy.h"
#include "core/search/search_queue.h"

namespace hpose {
namespace {

struct Node {
  int value;   // upper bound, or the exact value when tlevel == level == 0.
  int tlevel;  // theta block of 2^tlevel angle steps starting at itheta.
  int level;   // translation block of 2^level x 2^level lattice steps starting at (a, b).
  int itheta;
  int a;
  int b;
  // The free-space part of the bound is still to be subtracted (when the node is popped).
  // Not part of the order: a loose value is >= the node's bound, so popping loose nodes first
  // and tightening them expands the same nodes in the same order as tight values would.
  bool loose;
};

constexpr std::uint64_t kOffsetMask = (std::uint64_t{1} << 24) - 1;

struct BranchAndBoundResult {
  bool found = false;
  LatticePose best;
  int value = 0;
  bool below_min = false;  // stopped: no pose reaches min_value.
  int upper_bound = 0;     // with below_min: no pose's value exceeds this.
};

// The value of poses and its bounds for one template (or one slab of a tall one): weighted
// cluster hits (OR pyramid: an upper bound) minus weighted free-space hits (AND pyramid over
// cell-disjoint column masks: a lower bound of the free hits of a single rotation; theta blocks
// bound the free hits by 0).
class PartEvaluator {
 public:
  PartEvaluator(const ColumnOccupancy* cluster, const ColumnOccupancy* free, int free_weight,
                int hit_weight, const TemplateRotations& rotations, bool swept_bounds,
                int free_bound_max_level, bool common_free_part, bool common_pair_free_part)
      : cluster_(cluster),
        free_(free),
        free_weight_(free_weight),
        hit_weight_(hit_weight),
        rotations_(&rotations),
        grouped_(cluster->aligned() && (free == nullptr || free->aligned()) &&
                 rotations.has_cell_groups()),
        pairs_ok_(grouped_ && rotations.lattice().subdivisions >= 4),
        swept_ok_(swept_bounds && cluster->aligned() && rotations.has_cell_groups()),
        common_ok_(swept_ok_ && free != nullptr && free->aligned() && common_free_part),
        common_pairs_ok_(common_ok_ && common_pair_free_part),
        free_bound_max_level_(free_bound_max_level) {}

  int Value(int itheta, int a, int b) const {
    int hits = 0, free_hits = 0;
    AddCounts(itheta, a, b, &hits, &free_hits);
    return hit_weight_ * hits - free_weight_ * free_hits;
  }
  // The cluster part of a block's bound: with HasFreePart, FreePart is still to be subtracted.
  int ClusterBound(int tlevel, int itheta, int a, int b, int level) const {
    if (Swept(level)) {
      const int mask = rotations_->lattice().subdivisions - 1;
      return hit_weight_ *
             cluster_->HitsGrouped(
                 rotations_->SweptTable(tlevel, itheta, level, a & mask, b & mask), a, b);
    }
    const RotatedTemplate& r = rotations_->GetBlock(tlevel, itheta);
    if (Pairs(r, a, b, level)) {
      return hit_weight_ *
             cluster_->PairBound(PairTable(itheta, a, b), r.column_masks.data(), a, b);
    }
    return hit_weight_ * cluster_->Bound(r, a, b, level);
  }
  // The four translation quarters' ClusterBound, added to out[].
  void AddClusterBound4(int tlevel, int itheta, int a, int b, int level, int out[4]) const {
    const int size = 1 << level;
    const int s = rotations_->lattice().subdivisions;
    int part[4];
    if (Swept(level) && size % s == 0) {  // the four share a residue: one table.
      cluster_->HitsGrouped4(
          rotations_->SweptTable(tlevel, itheta, level, a & (s - 1), b & (s - 1)), a, b, size / s,
          part);
      for (int k = 0; k < 4; ++k) out[k] += hit_weight_ * part[k];
      return;
    }
    const RotatedTemplate& r = rotations_->GetBlock(tlevel, itheta);
    if (Swept(level) || Pairs(r, a, b, level)) {
      for (int i = 0; i < 2; ++i) {
        for (int j = 0; j < 2; ++j) {
          out[2 * i + j] += ClusterBound(tlevel, itheta, a + i * size, b + j * size, level);
        }
      }
      return;
    }
    cluster_->Bound4(r, a, b, level, part);
    for (int k = 0; k < 4; ++k) out[k] += hit_weight_ * part[k];
  }
  // Asks the caches for the start of the table the bound (or, at a single pose, the value) of
  // the block will read, so that the tables a node's expansion reads load side by side instead
  // of one miss after another (they are scattered over tens of MB). A table not made yet (the
  // tables made on first use) is left to its first use: the block may never be bounded.
  void Prefetch(int tlevel, int itheta, int a, int b, int level) const {
    if (!swept_ok_ || level > TemplateRotations::kSweptLevels) return;
    const int mask = rotations_->lattice().subdivisions - 1;
    PrefetchStart(rotations_->SweptTableIfMade(tlevel, itheta, level, a & mask, b & mask));
  }
  // The same for the table FreePart reads (theta blocks; with HasFreePart).
  void PrefetchFreePart(int tlevel, int itheta, int a, int b, int level) const {
    if (tlevel == 0) return;
    const int mask = rotations_->lattice().subdivisions - 1;
    PrefetchStart(level > 0 ? rotations_->CommonPairTableIfMade(tlevel, itheta, a & mask, b & mask)
                            : rotations_->CommonTableIfMade(tlevel, itheta, a & mask, b & mask));
  }

  static void PrefetchStart(const CellTable& g) {
    for (int i = 0; i < g.prefetch_words; i += 8) __builtin_prefetch(g.words + i);
  }

  // Single rotations over blocks of 2 .. 2^free_bound_max_level steps; theta blocks at single
  // translations (with their common cells) and, with theta_block_pair_free_part, over blocks of
  // 2 steps (with the cells common to their four translations) when the layouts allow.
  bool HasFreePart(int tlevel, int level) const {
    if (free_ == nullptr) return false;
    if (tlevel > 0) {
      return (level == 0 && common_ok_) ||
             (level == 1 && common_pairs_ok_ && free_bound_max_level_ >= 1);
    }
    return level > 0 && level <= free_bound_max_level_;
  }
  // Weighted lower bound of the free hits of the block's poses (with HasFreePart).
  int FreePart(int tlevel, int itheta, int a, int b, int level) const {
    if (tlevel > 0 && level > 0) {  // the voxels every pose of the block places.
      const int mask = rotations_->lattice().subdivisions - 1;
      return free_weight_ *
             free_->HitsGrouped(rotations_->CommonPairTable(tlevel, itheta, a & mask, b & mask), a,
                                b);
    }
    if (tlevel > 0) {  // the voxels every rotation of the block places at (a, b).
      const int mask = rotations_->lattice().subdivisions - 1;
      return free_weight_ *
             free_->HitsGrouped(rotations_->CommonTable(tlevel, itheta, a & mask, b & mask), a, b);
    }
    const RotatedTemplate& r = rotations_->Get(itheta);
    if (Pairs(r, a, b, level)) {
      return free_weight_ * free_->PairBound(PairTable(itheta, a, b),
                                             rotations_->DisjointMasks(itheta).data(), a, b);
    }
    return free_weight_ *
           free_->LowerBound(r, rotations_->DisjointMasks(itheta).data(), a, b, level);
  }
  // Adds the pose's hits and free hits (the occupancies' scratch space untouched when grouped).
  void AddCounts(int itheta, int a, int b, int* hits, int* free_hits) const {
    if (grouped_) {
      const int mask = rotations_->lattice().subdivisions - 1;
      const CellTable g = rotations_->SweptTable(0, itheta, 0, a & mask, b & mask);
      *hits += cluster_->HitsGrouped(g, a, b);
      *free_hits += free_ != nullptr ? free_->HitsGrouped(g, a, b) : 0;
      return;
    }
    const RotatedTemplate& r = rotations_->Get(itheta);
    *hits += cluster_->Hits(r, a, b);
    *free_hits += free_ != nullptr ? free_->Hits(r, a, b) : 0;
  }

 private:
  // Blocks of 1 .. 2^kSweptLevels steps take the swept bound of their rotations when asked for
  // and the layout allows (the lookups of its cells stay within the aligned range, as the
  // columns' windows do). Single translations are bounded so only as theta blocks (single poses
  // are evaluated).
  bool Swept(int level) const {
    return swept_ok_ && level >= 0 && level <= TemplateRotations::kSweptLevels;
  }
  // Blocks of two steps of a single rotation take the PairBound path when the layouts allow.
  bool Pairs(const RotatedTemplate& r, int a, int b, int level) const {
    return level == 1 && pairs_ok_ && r.column_extent.empty() && ((a | b) & 1) == 0;
  }
  const PairBlockTable& PairTable(int itheta, int a, int b) const {
    const int mask = rotations_->lattice().subdivisions - 1;
    return rotations_->PairTable(itheta, a & mask, b & mask);
  }

  const ColumnOccupancy* cluster_;
  const ColumnOccupancy* free_;  // may be null.
  int free_weight_;
  int hit_weight_;
  const TemplateRotations* rotations_;
  bool grouped_;  // exact values from the cell groups.
  bool pairs_ok_;
  bool swept_ok_;
  bool common_ok_;
  bool common_pairs_ok_;
  int free_bound_max_level_;
};

// The value and bounds of a template: its one PartEvaluator, or the sum over a tall template's
// slabs (TemplateRotations::slabs: disjoint z cells, so hits, free hits and their bounds add).
class Evaluator {
 public:
  explicit Evaluator(std::vector<PartEvaluator> parts) : parts_(std::move(parts)) {}

  int Value(int itheta, int a, int b) const {
    int v = 0;
    for (const PartEvaluator& p : parts_) v += p.Value(itheta, a, b);
    return v;
  }
  int ClusterBound(int tlevel, int itheta, int a, int b, int level) const {
    int v = 0;
    for (const PartEvaluator& p : parts_) v += p.ClusterBound(tlevel, itheta, a, b, level);
    return v;
  }
  void ClusterBound4(int tlevel, int itheta, int a, int b, int level, int out[4]) const {
    for (int k = 0; k < 4; ++k) out[k] = 0;
    for (const PartEvaluator& p : parts_) p.AddClusterBound4(tlevel, itheta, a, b, level, out);
  }
  void Prefetch(int tlevel, int itheta, int a, int b, int level) const {
    for (const PartEvaluator& p : parts_) p.Prefetch(tlevel, itheta, a, b, level);
  }
  void PrefetchFreePart(int tlevel, int itheta, int a, int b, int level) const {
    for (const PartEvaluator& p : parts_) {
      if (p.HasFreePart(tlevel, level)) p.PrefetchFreePart(tlevel, itheta, a, b, level);
    }
  }
  bool HasFreePart(int tlevel, int level) const {
    for (const PartEvaluator& p : parts_) {
      if (p.HasFreePart(tlevel, level)) return true;
    }
    return false;
  }
  int FreePart(int tlevel, int itheta, int a, int b, int level) const {
    int v = 0;
    for (const PartEvaluator& p : parts_) {
      if (p.HasFreePart(tlevel, level)) v += p.FreePart(tlevel, itheta, a, b, level);
    }
    return v;
  }
  void Counts(int itheta, int a, int b, int* hits, int* free_hits) const {
    *hits = 0;
    *free_hits = 0;
    for (const PartEvaluator& p : parts_) p.AddCounts(itheta, a, b, hits, free_hits);
  }

 private:
  std::vector<PartEvaluator> parts_;
};

// A search's queue and the nodes it defers. A search pushes tens of thousands of nodes; their
// memory is reused search after search rather than allocated anew: searches take the buffers
// from a pool and give them back when done. A search whose runner-up is pending keeps its own,
// so several may be out at once.
struct QueueBuffers {
  SearchQueue queue;
  std::vector<PackedNode> deferred;
};

class QueuePool {
 public:
  static std::unique_ptr<QueueBuffers> Take() {
    QueuePool& pool = Instance();
    {
      const std::lock_guard<std::mutex> lock(pool.mutex_);
      if (!pool.free_.empty()) {
        std::unique_ptr<QueueBuffers> b = std::move(pool.free_.back());
        pool.free_.pop_back();
        return b;
      }
    }
    return std::make_unique<QueueBuffers>();
  }
  static void Give(std::unique_ptr<QueueBuffers> b) {
    b->queue.clear();
    b->deferred.clear();
    QueuePool& pool = Instance();
    const std::lock_guard<std::mutex> lock(pool.mutex_);
    if (pool.free_.size() < kKept) pool.free_.push_back(std::move(b));
  }
  // Makes sure `queues` buffers (at most kKept) are kept, each with room written for `blocks`
  // queued and as many deferred nodes.
  static void Reserve(int queues, size_t blocks) {
    QueuePool& pool = Instance();
    const std::lock_guard<std::mutex> lock(pool.mutex_);
    const size_t n = std::min(static_cast<size_t>(std::max(queues, 0)), kKept);
    while (pool.free_.size() < n) pool.free_.push_back(std::make_unique<QueueBuffers>());
    for (size_t i = 0; i < n; ++i) {
      QueueBuffers& b = *pool.free_[i];
      b.queue.Reserve(blocks);
      b.deferred.resize(std::max(blocks, b.deferred.size()));
      b.deferred.clear();
    }
  }

 private:
  static constexpr size_t kKept = 16;  // more than the searches of a frame held at once.
  static QueuePool& Instance() {
    static QueuePool pool;
    return pool;
  }
  std::mutex mutex_;
  std::vector<std::unique_ptr<QueueBuffers>> free_;
};

// Best-first branch and bound over thetas and the translation region. Next() returns the
// best remaining pose among the currently allowed thetas; calling it again with fewer thetas
// allowed continues from the same queue (the runner-up search reuses every bound computed for
// the best).
class BranchAndBound {
 public:
  BranchAndBound(const Evaluator* eval, const TemplateRotations& rotations,
                 const ExactSearch::Region& region, int top_level, int top_tlevel, int min_value,
                 int defer_below, int theta_split_lead, double theta_split_ratio,
                 SearchResult* counters)
      : eval_(*eval),
        rotations_(rotations),
        region_(region),
        min_value_(min_value),
        counters_(counters),
        steps_(rotations.lattice().angle_steps),
        allowed_(steps_, true),
        defer_below_(defer_below),
        theta_split_lead_(theta_split_lead),
        theta_split_ratio_(theta_split_ratio) {
    top_tlevel = std::clamp(top_tlevel, 0, TemplateRotations::kThetaLevels - 1);
    while (top_tlevel > 0 && (1 << top_tlevel) > steps_) --top_tlevel;
    const int block = 1 << top_level;
    for (int itheta = 0; itheta < steps_; itheta += 1 << top_tlevel) {
      for (int a = region.ix_min; a <= region.ix_max; a += block) {
        for (int b = region.iy_min; b <= region.iy_max; b += block) {
          Push(top_tlevel, itheta, top_level, a, b);
        }
      }
    }
  }

  ~BranchAndBound() { QueuePool::Give(std::move(buffers_)); }
  BranchAndBound(const BranchAndBound&) = delete;
  BranchAndBound& operator=(const BranchAndBound&) = delete;

  // After Next() stopped below min_value: the best pose whose exact value was computed, or
  // (when none was) the pose reached by following the highest child bound down from the best
  // remaining node, evaluated exactly. Always a real pose of the lattice with its exact value.
  // The nodes it takes from the queue go back to it afterwards (their subtrees bounded again
  // when expanded), so that the search can still be lowered.
  BranchAndBoundResult BestEvaluated() {
    if (best_exact_.found) return best_exact_;
    defer_below_ = std::numeric_limits<int>::min();  // nothing is deferred from here on.
    MergeDeferredIfNeeded();
    std::vector<PackedNode> taken;
    while (!best_exact_.found && !Empty()) {
      taken.push_back(Top());
      Node n = Unpack(Top());
      Pop();
      if (!AnyAllowed(n.itheta, n.tlevel)) continue;
      while (n.tlevel > 0 || n.level > 0) {  // one child a level, the highest bound's.
        Node children[4];
        const int count = Children(n, children);
        if (count == 0) break;
        n = *std::max_element(children, children + count,
                              [](const Node& x, const Node& y) { return x.value < y.value; });
      }
    }
    for (const PackedNode& p : taken) queue_.push(p);
    return best_exact_;
  }

  // After Next(): goes on down to a lower `min_value`, from the node it stopped at and the rest
  // of the queue (it stopped below min_value), or for the next optimum (it found one).
  void Lower(int min_value) {
    min_value_ = min_value;
    if (has_stopped_) Enqueue(stopped_);
    has_stopped_ = false;
  }

  // Before Next() (not after it stopped): nothing below `min_value` is wanted any more (a
  // lower one leaves the search's own).
  void Raise(int min_value) { min_value_ = std::max(min_value_, min_value); }

  void set_allowed(std::vector<bool> allowed) {
    allowed_ = std::move(allowed);
    all_allowed_ = false;
  }

  BranchAndBoundResult Next() {
    BranchAndBoundResult out;
    for (MergeDeferredIfNeeded(); !Empty(); MergeDeferredIfNeeded()) {
      Node n = Unpack(Top());
      Pop();
      if (!AnyAllowed(n.itheta, n.tlevel)) continue;
      PrefetchTables(n);
      if (n.loose) {  // subtract the free-space part now.
        n.value -= eval_.FreePart(n.tlevel, n.itheta, n.a, n.b, n.level);
        n.loose = false;
        // Still of the queue's highest value (deferred ones are below defer_below_): go on with
        // it rather than push and pop it (it would leave first: the last block pushed of a value
        // leaves first); the blocks expanded are the same.
        if (n.value < defer_below_ || (!Empty() && n.value < queue_.top_value())) {
          Enqueue(n);
          continue;
        }
      }
      if (n.value < min_value_) {  // the best that remains cannot reach min_value.
        stopped_ = n;
        has_stopped_ = true;
        out.below_min = true;
        out.upper_bound = n.value;
        return out;
      }
      if (n.tlevel == 0 && n.level == 0) {
        out.found = true;
        out.best = LatticePose{n.a, n.b, n.itheta};
        out.value = n.value;
        return out;
      }
      // Headings first while SplitTheta says so (single rotations take the tighter bounds), then
      // single poses, else the four translation quarters.
      if (SplitTheta(n)) {
        const int half = 1 << (n.tlevel - 1);
        Push(n.tlevel - 1, n.itheta, n.level, n.a, n.b);
        Push(n.tlevel - 1, n.itheta + half, n.level, n.a, n.b);
      } else if (n.tlevel == 0 && n.level == 1) {
        for (int da : {0, 1}) {
          for (int db : {0, 1}) Push(0, n.itheta, 0, n.a + da, n.b + db);
        }
      } else {
        PushQuarters(n);
      }
    }
    return out;
  }

 private:
  // Whether the node is split in theta (else in translation).
  bool SplitTheta(const Node& n) const {
    if (n.tlevel == 0) return false;
    if (n.level == 0) return true;
    if (theta_split_ratio_ > 0.0) {
      return rotations_.block_extent(n.tlevel) >= theta_split_ratio_ * (1 << n.level);
    }
    return n.tlevel + theta_split_lead_ >= n.level;
  }

  // Asks the caches for the starts of the tables that tightening the popped node (its free-space
  // part) and expanding it (its children's bounds, split as Next splits it) read, all at once,
  // before the first of them is read: their misses overlap instead of following one another.
  // Half the time of the bounds of theta blocks of 2 and 4 headings (the tables least often in
  // the caches) was waiting for them.
  void PrefetchTables(const Node& n) const {
    if (n.loose) eval_.PrefetchFreePart(n.tlevel, n.itheta, n.a, n.b, n.level);
    if (n.tlevel == 0 && n.level == 0) return;
    if (SplitTheta(n)) {
      const int half = 1 << (n.tlevel - 1);
      eval_.Prefetch(n.tlevel - 1, n.itheta, n.a, n.b, n.level);
      if (n.itheta + half < steps_)
        eval_.Prefetch(n.tlevel - 1, n.itheta + half, n.a, n.b, n.level);
      return;
    }
    const int half = 1 << (n.level - 1);
    if (half >= rotations_.lattice().subdivisions) {  // the quarters share a residue: one table.
      eval_.Prefetch(n.tlevel, n.itheta, n.a, n.b, n.level - 1);
      return;
    }
    for (int i = 0; i < 2; ++i) {
      for (int j = 0; j < 2; ++j) {
        eval_.Prefetch(n.tlevel, n.itheta, n.a + i * half, n.b + j * half, n.level - 1);
      }
    }
  }

  // Whether any allowed theta lies in [itheta, itheta + 2^tlevel).
  bool AnyAllowed(int itheta, int tlevel) const {
    if (all_allowed_) return true;
    for (int t = itheta; t < std::min(steps_, itheta + (1 << tlevel)); ++t) {
      if (allowed_[t]) return true;
    }
    return false;
  }

  // The four translation quarters of a block (a bound each, whatever the block's level), bounded
  // in one pass over the columns; pushed in the order Push would push them.
  void PushQuarters(const Node& n) {
    const int level = n.level - 1;
    const int half = 1 << level;
    int cluster_bounds[4];
    eval_.ClusterBound4(n.tlevel, n.itheta, n.a, n.b, level, cluster_bounds);
    const bool loose = eval_.HasFreePart(n.tlevel, level);
    for (int i = 0; i < 2; ++i) {
      for (int j = 0; j < 2; ++j) {
        const int a = n.a + i * half, b = n.b + j * half;
        if (a > region_.ix_max || b > region_.iy_max) continue;
        ++counters_->bounds_evaluated;
        Enqueue({cluster_bounds[2 * i + j], n.tlevel, level, n.itheta, a, b, loose});
      }
    }
  }

  void Enqueue(const Node& n) {
    const PackedNode p = Pack(n);
    if (n.value < defer_below_) {
      deferred_.push_back(p);
      return;
    }
    queue_.push(p);
  }

  PackedNode Pack(const Node& n) const {
    const int fine = n.tlevel + n.level;
    const std::uint64_t da = static_cast<std::uint64_t>(n.a - region_.ix_min);
    const std::uint64_t db = static_cast<std::uint64_t>(n.b - region_.iy_min);
    assert(da <= kOffsetMask && db <= kOffsetMask && n.itheta < 0x10000 && fine < 32);
    assert(n.tlevel < 8 && n.level < 32);
    PackedNode p;
    p.hi = (static_cast<std::uint64_t>(static_cast<std::uint32_t>(n.value) ^ 0x80000000u) << 32) |
           (static_cast<std::uint64_t>(fine) << PackedNode::kFineShift) |
           static_cast<std::uint64_t>(0xFFFF - n.itheta);
    p.lo = ((kOffsetMask - da) << 40) | ((kOffsetMask - db) << 16) |
           (static_cast<std::uint64_t>(7 - n.tlevel) << 13) |
           (static_cast<std::uint64_t>(n.level) << 8) | (n.loose ? 1 : 0);
    return p;
  }

  bool Empty() const { return queue_.empty(); }
  const PackedNode& Top() const { return queue_.top(); }
  void Pop() { queue_.pop(); }
  // Brings the deferred nodes in when the heap's best no longer beats them: the pop order is
  // then the order without deferral.
  void MergeDeferredIfNeeded() {
    if (deferred_.empty()) return;
    if (!queue_.empty() && queue_.top_value() >= defer_below_) return;
    for (const PackedNode& p : deferred_) queue_.push(p);
    deferred_.clear();
    defer_below_ = std::numeric_limits<int>::min();
  }
  static int UnpackValue(const PackedNode& p) { return SearchQueue::Value(p); }

  Node Unpack(const PackedNode& p) const {
    Node n;
    n.value = UnpackValue(p);
    n.itheta = 0xFFFF - static_cast<int>(p.hi & 0xFFFF);
    n.a = region_.ix_min + static_cast<int>(kOffsetMask - (p.lo >> 40));
    n.b = region_.iy_min + static_cast<int>(kOffsetMask - ((p.lo >> 16) & kOffsetMask));
    n.tlevel = 7 - static_cast<int>((p.lo >> 13) & 7);
    n.level = static_cast<int>((p.lo >> 8) & 31);
    n.loose = (p.lo & 1) != 0;
    return n;
  }

  void Push(int tlevel, int itheta, int level, int a, int b) {
    Node n;
    if (MakeNode(tlevel, itheta, level, a, b, &n)) Enqueue(n);
  }

  // The node of the block with its bound (a single pose: its exact value, which it also offers
  // as the best evaluated), or false when the block lies outside the region or the allowed
  // thetas.
  bool MakeNode(int tlevel, int itheta, int level, int a, int b, Node* out) {
    if (a > region_.ix_max || b > region_.iy_max || itheta >= steps_) return false;
    if (!AnyAllowed(itheta, tlevel)) return false;
    if (tlevel == 0 && level == 0) {
      ++counters_->poses_evaluated;
      const int value = eval_.Value(itheta, a, b);
      if (!best_exact_.found || value > best_exact_.value) {
        best_exact_.found = true;
        best_exact_.value = value;
        best_exact_.best = LatticePose{a, b, itheta};
      }
      *out = {value, 0, 0, itheta, a, b, false};
    } else {
      ++counters_->bounds_evaluated;
      *out = {eval_.ClusterBound(tlevel, itheta, a, b, level),
              tlevel,
              level,
              itheta,
              a,
              b,
              eval_.HasFreePart(tlevel, level)};
    }
    return true;
  }

  // The halves in theta or the quarters in translation of a node (as Next splits it), with
  // their free-space parts subtracted; returns how many lie within the region and the allowed
  // thetas.
  int Children(const Node& n, Node out[4]) {
    int count = 0;
    if (SplitTheta(n)) {
      const int half = 1 << (n.tlevel - 1);
      for (int t : {0, half}) {
        count += MakeNode(n.tlevel - 1, n.itheta + t, n.level, n.a, n.b, &out[count]) ? 1 : 0;
      }
    } else {
      const int half = 1 << (n.level - 1);
      for (int da : {0, half}) {
        for (int db : {0, half}) {
          count +=
              MakeNode(n.tlevel, n.itheta, n.level - 1, n.a + da, n.b + db, &out[count]) ? 1 : 0;
        }
      }
    }
    for (int k = 0; k < count; ++k) {
      if (!out[k].loose) continue;
      out[k].value -=
          eval_.FreePart(out[k].tlevel, out[k].itheta, out[k].a, out[k].b, out[k].level);
      out[k].loose = false;
    }
    return count;
  }

  const Evaluator& eval_;
  const TemplateRotations& rotations_;
  const ExactSearch::Region region_;
  int min_value_;
  Node stopped_{};  // the node Next() stopped at (has_stopped_), for Lower.
  bool has_stopped_ = false;
  SearchResult* counters_;
  const int steps_;
  std::vector<bool> allowed_;
  bool all_allowed_ = true;
  // The queue, plus nodes kept out of it while they cannot beat the incumbent: they join it
  // once its best falls below defer_below_. From QueuePool, given back by the destructor.
  std::unique_ptr<QueueBuffers> buffers_ = QueuePool::Take();
  SearchQueue& queue_ = buffers_->queue;
  std::vector<PackedNode>& deferred_ = buffers_->deferred;
  int defer_below_;
  const int theta_split_lead_;
  const double theta_split_ratio_;
  BranchAndBoundResult best_exact_;  // the best exactly evaluated pose so far.
};

// Fills the result's pose, value, hits and scores from a found lattice pose.
void SetPose(const BranchAndBoundResult& found, const Evaluator& eval, const PoseLattice& lattice,
             int n, int n_weighted, SearchResult* result) {
  result->best = found.best;
  result->pose = ToPose(lattice, found.best);
  result->value = found.value;
  eval.Counts(found.best.itheta, found.best.ix, found.best.iy, &result->hits, &result->free_hits);
  result->score = 100.0 * found.value / n_weighted;
  result->coverage = 100.0 * result->hits / n;
}

}  // namespace

bool ExactSearch::BySlabs(const TemplateRotations& rotations) const {
  return options_.slabs && !rotations.has_cell_groups() && !rotations.slabs().empty();
}

double ExactSearch::Margin(const TemplateRotations& rotations) const {
  if (options_.margin_m >= 0.0) return options_.margin_m;
  // Horizontal radius of the template from its rotation at theta = 0.
  return options_.auto_margin_fraction * rotations.rim_radius_m() +
         rotations.lattice().resolution_m;
}

double ExactSearch::OriginMargin(const TemplateRotations& rotations) const {
  // The region's low ends are rounded down to whole cells, its high ends up to a step.
  return Margin(rotations) + rotations.lattice().resolution_m + rotations.lattice().step_m();
}

ExactSearch::Region ExactSearch::TranslationRegion(const ClusterVoxels& cluster,
                                                   const TemplateRotations& rotations) const {
  Region r;
  if (cluster.cells.empty()) return r;
  const PoseLattice& lattice = rotations.lattice();
  int x_lo = cluster.cells.front().x(), x_hi = x_lo;
  int y_lo = cluster.cells.front().y(), y_hi = y_lo;
  for (const Eigen::Vector3i& c : cluster.cells) {
    x_lo = std::min(x_lo, c.x());
    x_hi = std::max(x_hi, c.x());
    y_lo = std::min(y_lo, c.y());
    y_hi = std::max(y_hi, c.y());
  }
  const double margin = Margin(rotations);
  const double res = lattice.resolution_m;
  const double step = lattice.step_m();
  // Starting at a multiple of the subdivisions, every block of at least that many steps does
  // too (ColumnOccupancy's aligned bounds).
  const int s = lattice.subdivisions;
  r.ix_min = s * FloorDiv(static_cast<int>(std::floor((x_lo * res - margin) / step)), s);
  r.ix_max = static_cast<int>(std::ceil(((x_hi + 1) * res + margin) / step));
  r.iy_min = s * FloorDiv(static_cast<int>(std::floor((y_lo * res - margin) / step)), s);
  r.iy_max = static_cast<int>(std::ceil(((y_hi + 1) * res + margin) / step));
  return r;
}

struct ExactSearch::GridNeeds {
  Region region;
  int top = 0;      // the top translation level.
  int arc_top = 0;  // the highest occupancy level the bounds read.
  int free_top = 0;
  int z_base = 0, z_words = 0;
  ColumnOccupancy::CellRange lookups;
};

ExactSearch::GridNeeds ExactSearch::Needs(const Region& region,
                                          const TemplateRotations& rotations) const {
  GridNeeds needs;
  needs.region = region;
  const int span = std::max(region.ix_max - region.ix_min, region.iy_max - region.iy_min) + 1;
  int& top = needs.top;
  while (top < options_.max_level && (1 << top) < span) ++top;
  const RotatedTemplate& r0 = rotations.Get(0);
  needs.z_base = r0.z_base;
  needs.z_words = r0.z_words;
  // Theta blocks' columns sweep their arcs too: with theta blocks, levels up to the one sweeping
  // the top block plus the widest arc.
  needs.arc_top = top;
  while (options_.top_theta_level > 0 &&
         (1 << needs.arc_top) - 1 < (1 << top) - 1 + rotations.max_block_extent()) {
    ++needs.arc_top;
  }
  // Free-space lower bounds are taken up to free_bound_max_level only (PairBound: level 1).
  needs.free_top = std::max(1, std::min(top, options_.free_bound_max_level));
  // Where bound windows start: any column's cell plus any block's (quarters of the last block
  // reach one top block past the region; exact hits' cell groups one cell more).
  const int s = rotations.lattice().subdivisions;
  ColumnOccupancy::CellRange& lookups = needs.lookups;
  lookups.x_lo = FloorDiv(region.ix_min, s) + FloorDiv(rotations.column_q_min().x(), s);
  lookups.y_lo = FloorDiv(region.iy_min, s) + FloorDiv(rotations.column_q_min().y(), s);
  lookups.x_hi =
      FloorDiv(region.ix_max + (1 << top), s) + FloorDiv(rotations.column_q_max().x(), s) + 1;
  lookups.y_hi =
      FloorDiv(region.iy_max + (1 << top), s) + FloorDiv(rotations.column_q_max().y(), s) + 1;
  return needs;
}

// One cluster's occupancies for the searches of several templates: levels and lookup range
// enough for each (more of either changes no bound: the same cells, the same windows).
struct SearchGrids {
  int z_base = 0, z_words = 0, levels = 0, free_levels = 0;
  ColumnOccupancy::CellRange lookups;
  std::unique_ptr<ColumnOccupancy> occ;
  std::unique_ptr<ColumnOccupancy> free;  // null without free space.
  // Tall templates instead: per slab index, the grids of the templates' slabs (null entries:
  // none shared); occ and free are then null.
  std::vector<std::shared_ptr<const SearchGrids>> slabs;

  bool Serves(int z_base_, int z_words_, int arc_top, int free_top, bool with_free,
              const ColumnOccupancy::CellRange& r) const {
    return z_base_ == z_base && z_words_ == z_words && arc_top <= levels &&
           (free == nullptr || free_top <= free_levels) && with_free == (free != nullptr) &&
           r.x_lo >= lookups.x_lo && r.x_hi <= lookups.x_hi && r.y_lo >= lookups.y_lo &&
           r.y_hi <= lookups.y_hi;
  }
};

std::shared_ptr<const SearchGrids> ExactSearch::MakeGrids(
    const ClusterVoxels& cluster, const ClusterVoxels* free_space,
    const std::vector<const TemplateRotations*>& rotations) const {
  if (rotations.empty() || cluster.cells.empty()) return nullptr;
  std::vector<Region> regions;
  for (const TemplateRotations* rot : rotations)
    regions.push_back(TranslationRegion(cluster, *rot));
  if (!BySlabs(*rotations[0])) return MakeGridsIn(cluster, free_space, rotations, regions);
  const std::vector<std::unique_ptr<TemplateRotations>>& first_slabs = rotations[0]->slabs();
  // Tall templates: the grids of their k-th slabs shared, each slab searched over its whole
  // template's region (null where the slabs' z layouts differ: those searches make their own).
  auto grids = std::make_shared<SearchGrids>();
  for (size_t k = 0; k < first_slabs.size(); ++k) {
    std::vector<const TemplateRotations*> slab_k;
    for (const TemplateRotations* rot : rotations) {
      if (!BySlabs(*rot) || rot->slabs().size() != first_slabs.size()) return nullptr;
      slab_k.push_back(rot->slabs()[k].get());
    }
    grids->slabs.push_back(MakeGridsIn(cluster, free_space, slab_k, regions));
  }
  return grids;
}

std::shared_ptr<const SearchGrids> ExactSearch::MakeGridsIn(
    const ClusterVoxels& cluster, const ClusterVoxels* free_space,
    const std::vector<const TemplateRotations*>& rotations,
    const std::vector<Region>& regions) const {
  auto grids = std::make_shared<SearchGrids>();
  for (size_t i = 0; i < rotations.size(); ++i) {
    const TemplateRotations& rot = *rotations[i];
    if (!rot.has_cell_groups()) return nullptr;  // its exact values would read Hits' scratch.
    const GridNeeds needs = Needs(regions[i], rot);
    if (needs.region.ix_max < needs.region.ix_min) return nullptr;
    if (i == 0) {
      grids->z_base = needs.z_base;
      grids->z_words = needs.z_words;
      grids->lookups = needs.lookups;
    } else if (needs.z_base != grids->z_base || needs.z_words != grids->z_words ||
               rot.lattice().resolution_m != rotations[0]->lattice().resolution_m ||
               rot.lattice().subdivisions != rotations[0]->lattice().subdivisions) {
      return nullptr;
    }
    grids->levels = std::max(grids->levels, needs.arc_top);
    grids->free_levels = std::max(grids->free_levels, needs.free_top);
    ColumnOccupancy::CellRange& l = grids->lookups;
    l.x_lo = std::min(l.x_lo, needs.lookups.x_lo);
    l.y_lo = std::min(l.y_lo, needs.lookups.y_lo);
    l.x_hi = std::max(l.x_hi, needs.lookups.x_hi);
    l.y_hi = std::max(l.y_hi, needs.lookups.y_hi);
  }
  const PoseLattice& lattice = rotations[0]->lattice();
  grids->occ = std::make_unique<ColumnOccupancy>(cluster, lattice, grids->z_base, grids->z_words,
                                                 grids->levels, ColumnOccupancy::Filter::kMax,
                                                 &grids->lookups);
  if (free_space != nullptr) {
    grids->free = std::make_unique<ColumnOccupancy>(*free_space, lattice, grids->z_base,
                                                    grids->z_words, grids->free_levels,
                                                    ColumnOccupancy::Filter::kMin, &grids->lookups);
  }
  if (!grids->occ->aligned() || (grids->free != nullptr && !grids->free->aligned())) {
    return nullptr;
  }
  return grids;
}

namespace {

// The rest of an exact search once its optimum is known: the same branch and bound, continued
// over the headings more than 30 degrees from the optimum's. Owns what the search made for
// itself (grids, evaluator, queue) and counts its own poses and bounds.
class ExactRunnerUp final : public RunnerUpSearch {
 public:
  ExactRunnerUp(const PoseLattice& lattice, int n_weighted)
      : lattice_(lattice), n_weighted_(n_weighted) {}

  void Find(SearchResult* result) override {
    if (bnb == nullptr) return;
    counters = SearchResult();
    std::vector<bool> others(lattice_.angle_steps, false);
    for (int t = 0; t < lattice_.angle_steps; ++t) {
      const double sep = std::abs(
          AngleDiff(t * lattice_.angle_step_rad(), best_itheta * lattice_.angle_step_rad()));
      others[t] = sep > kRunnerUpMinSeparationRad;
    }
    bnb->set_allowed(std::move(others));
    // Only the runner-ups within the window of the optimum are wanted.
    bnb->Raise(static_cast<int>(
        std::max<std::int64_t>(static_cast<std::int64_t>(best_value) - runner_up_window,
                               std::numeric_limits<int>::min())));
    const BranchAndBoundResult runner = bnb->Next();
    if (runner.found) {
      result->has_runner_up = true;
      result->runner_up_pose = ToPose(lattice_, runner.best);
      result->runner_up_score = 100.0 * runner.value / n_weighted_;
    } else if (runner.below_min) {
      result->runner_up_score = 100.0 * runner.upper_bound / n_weighted_;  // an upper bound only.
    }
    result->poses_evaluated += counters.poses_evaluated;
    result->bounds_evaluated += counters.bounds_evaluated;
    bnb.reset();  // its queue back to the pool.
  }

  // The branch and bound's next optimum into `result` (its counts added): the pose, or the
  // stop below min_value with the best pose evaluated. False when there is neither.
  bool Next(SearchResult* result) {
    const auto take_counts = [&] {
      result->poses_evaluated += counters.poses_evaluated;
      result->bounds_evaluated += counters.bounds_evaluated;
      counters = SearchResult();
    };
    const BranchAndBoundResult best = bnb->Next();
    take_counts();
    if (best.below_min) {
      result->below_min_value = true;
      result->value_upper_bound = best.upper_bound;
      result->score_upper_bound = 100.0 * best.upper_bound / n_weighted_;
      const BranchAndBoundResult found = bnb->BestEvaluated();
      take_counts();
      if (found.found) SetPose(found, *eval, lattice_, n, n_weighted_, result);
      return true;
    }
    if (!best.found) return false;
    SetPose(best, *eval, lattice_, n, n_weighted_, result);
    best_itheta = best.best.itheta;
    best_value = best.value;
    return true;
  }

  // What the search made for itself: grids (the cluster's when not shared), the evaluator that
  // reads them, and the branch and bound over them (in this order: each reads the one before).
  std::vector<std::unique_ptr<ColumnOccupancy>> own;
  std::unique_ptr<Evaluator> eval;
  SearchResult counters;  // the branch and bound's counts.
  std::unique_ptr<BranchAndBound> bnb;
  int best_itheta = 0;
  int best_value = 0;
  int n = 0;                                               // cluster voxels.
  int runner_up_window = std::numeric_limits<int>::max();  // SearchProblem::runner_up_window.

 private:
  const PoseLattice& lattice_;
  const int n_weighted_;
};

// A search stopped below its min_value, with its queue: lowered, the same branch and bound goes
// on from where it stopped.
class ExactStopped final : public StoppedSearch {
 public:
  ExactStopped(std::unique_ptr<ExactRunnerUp> state, const SearchResult& first)
      : state_(std::move(state)), first_(first) {}

  std::unique_ptr<RunnerUpSearch> Lower(int min_value, SearchResult* result) override {
    *result = SearchResult();
    result->incumbent_used = first_.incumbent_used;
    result->incumbent_value = first_.incumbent_value;
    result->poses_evaluated = first_.poses_evaluated;
    result->bounds_evaluated = first_.bounds_evaluated;
    if (state_ == nullptr) return nullptr;
    std::unique_ptr<ExactRunnerUp> state = std::move(state_);
    state->bnb->Lower(min_value);
    if (!state->Next(result) || result->below_min_value) return nullptr;
    return state;
  }

 private:
  std::unique_ptr<ExactRunnerUp> state_;
  SearchResult first_;
};

}  // namespace

void ExactSearch::ReserveQueues(int queues, size_t blocks) { QueuePool::Reserve(queues, blocks); }

SearchResult ExactSearch::Search(const SearchProblem& problem) const {
  SearchResult result;
  const std::unique_ptr<RunnerUpSearch> runner_up = SearchBest(problem, &result);
  if (runner_up != nullptr) runner_up->Find(&result);
  return result;
}

std::unique_ptr<RunnerUpSearch> ExactSearch::SearchBest(
    const SearchProblem& problem, SearchResult* out,
    std::unique_ptr<StoppedSearch>* stopped) const {
  SearchResult& result = *out;
  result = SearchResult();
  const ClusterVoxels& cluster = *problem.cluster;
  const TemplateRotations& rotations = *problem.rotations;
  const PoseLattice& lattice = rotations.lattice();
  const int n = problem.scorer->cluster_voxels();
  // The region is the whole template's; a tall template is evaluated slab by slab, each slab
  // with grids of its own z frame, levels and lookups.
  const Region region = TranslationRegion(cluster, rotations);
  if (region.ix_max < region.ix_min || n == 0) return nullptr;
  std::vector<const TemplateRotations*> parts;
  if (BySlabs(rotations)) {
    for (const std::unique_ptr<TemplateRotations>& slab : rotations.slabs())
      parts.push_back(slab.get());
  } else {
    parts.push_back(&rotations);
  }
  int top = 0;
  const int n_weighted = n * problem.hit_weight;  // the score's denominator.
  auto state = std::make_unique<ExactRunnerUp>(lattice, n_weighted);

  // Each part's cluster occupancy and its free space's: the shared ones when they serve it,
  // else made here.
  const bool with_free = problem.free_space != nullptr;
  std::vector<std::unique_ptr<ColumnOccupancy>>& own = state->own;
  std::vector<PartEvaluator> part_evaluators;
  for (size_t k = 0; k < parts.size(); ++k) {
    const TemplateRotations* part = parts[k];
    const GridNeeds needs = Needs(region, *part);
    top = needs.top;  // the region's: the same for every part.
    const ColumnOccupancy* occ_ptr = nullptr;
    const ColumnOccupancy* free_ptr = nullptr;
    const SearchGrids* shared = problem.grids;
    if (part != &rotations && shared != nullptr) {  // a slab: its index's grids, if any.
      shared = k < shared->slabs.size() ? shared->slabs[k].get() : nullptr;
    }
    if (shared != nullptr && shared->occ != nullptr &&
        shared->Serves(needs.z_base, needs.z_words, needs.arc_top, needs.free_top, with_free,
                       needs.lookups)) {
      occ_ptr = shared->occ.get();
      free_ptr = shared->free.get();
    } else {
      own.push_back(std::make_unique<ColumnOccupancy>(cluster, lattice, needs.z_base, needs.z_words,
                                                      needs.arc_top, ColumnOccupancy::Filter::kMax,
                                                      &needs.lookups));
      occ_ptr = own.back().get();
      if (with_free) {
        own.push_back(std::make_unique<ColumnOccupancy>(
            *problem.free_space, lattice, needs.z_base, needs.z_words, needs.free_top,
            ColumnOccupancy::Filter::kMin, &needs.lookups));
        free_ptr = own.back().get();
      }
    }
    part_evaluators.emplace_back(occ_ptr, free_ptr, problem.free_space_weight, problem.hit_weight,
                                 *part, options_.swept_bounds, options_.free_bound_max_level,
                                 options_.theta_block_free_part,
                                 options_.theta_block_pair_free_part);
  }
  state->eval = std::make_unique<Evaluator>(std::move(part_evaluators));
  const Evaluator& eval = *state->eval;

  // A known pose's value (e.g. the previous frame's): nodes whose bound cannot reach it stay
  // out of the queue until the search gets down to them (if ever). Same result, fewer heap
  // operations.
  const int stop_value = std::max(problem.min_value, problem.optimum_min_value);
  int defer_below = stop_value;
  if (problem.incumbent != nullptr) {
    const LatticePose& p = *problem.incumbent;
    if (p.ix >= region.ix_min && p.ix <= region.ix_max && p.iy >= region.iy_min &&
        p.iy <= region.iy_max && p.itheta >= 0 && p.itheta < lattice.angle_steps) {
      ++result.poses_evaluated;
      result.incumbent_value = eval.Value(p.itheta, p.ix, p.iy);
      result.incumbent_used = true;
      defer_below = std::max(defer_below, result.incumbent_value);
    }
  }
  state->bnb = std::make_unique<BranchAndBound>(
      &eval, rotations, region, top, options_.top_theta_level, stop_value, defer_below,
      options_.theta_split_lead, options_.theta_split_ratio, &state->counters);
  state->n = n;
  state->runner_up_window = problem.runner_up_window;
  if (!state->Next(&result)) return nullptr;
  if (result.below_min_value) {
    if (stopped != nullptr) *stopped = std::make_unique<ExactStopped>(std::move(state), result);
    return nullptr;
  }
  // The optimum reached optimum_min_value: its runner-up down to min_value.
  if (stop_value > problem.min_value) state->bnb->Lower(problem.min_value);
  return state;
}

}  // namespace hpose
