#ifndef HPOSE_CORE_SEARCH_EXACT_SEARCH_H_
#define HPOSE_CORE_SEARCH_EXACT_SEARCH_H_

#include <cstddef>

#include "core/search/pose_search.h"

namespace hpose {

struct ExactSearchOptions {
  // Translations searched: the template origin anywhere within the cluster's footprint grown
  // by this margin (metres). Negative: auto_margin_fraction x the template's horizontal radius
  // plus one voxel. The origin (below the torso centre) lies behind the seen surface by at most
  // the body's half depth, so half the radius (which a raised arm stretches) leaves room.
  double margin_m = -1.0;
  double auto_margin_fraction = 0.5;
  // Largest branch-and-bound block: 2^max_level lattice steps per side (4: 16 x 4 mm = 64 mm,
  // the largest block the swept tables bound). Larger top blocks take the arc bound, which costs
  // several times a swept one and, below blocks of 16 headings, prunes almost nothing: on the
  // real-time protocol's frames (medians) 6 gave 28.5 k bounds a frame (the tracked walk 12.0 k),
  // 5 28.2 k (12.0 k), 4 28.0 k (12.0 k), 3 36.0 k (17.9 k); 4 took about 0.93x the time of 6
  // (docs/BENCHMARKS.md), and its grids need two levels fewer.
  int max_level = 4;
  // Bound the cluster hits of blocks of 2 to 2^TemplateRotations::kSweptLevels steps of one
  // rotation by the cluster voxels the rotation reaches anywhere in the block
  // (TemplateRotations::SweptGroups: each voxel counted once) instead of the sum over its
  // columns (which counts a voxel once per column reaching it). Tighter where the block is a
  // cell or two wide; the same optimum (false: the column bound, as before).
  bool swept_bounds = true;
  // The free-space part of a block's bound (a lower bound of its free hits, subtracted when the
  // block leaves the queue) for single-rotation blocks of 2 .. 2^k steps only; larger blocks are
  // bounded by their cluster hits alone, still an upper bound (free hits are never negative).
  // The part costs a pass over the template's columns and seldom moves a block of several cells
  // below the optimum: 2 (blocks up to one 16 mm cell) does the least work on the real-time
  // protocol's frames with every result unchanged. 0: never; max_level or more: every block.
  int free_bound_max_level = 2;
  // A free-space part for theta blocks at single translations: the free cells that every
  // heading of the block places a voxel in (TemplateRotations::CommonBlockGroups).
  bool theta_block_free_part = true;
  // A free-space part for theta blocks over translation blocks of 2 x 2 steps too (with
  // free_bound_max_level >= 1): the free cells every pose of the block places a voxel in
  // (TemplateRotations::CommonPairGroups). It refutes blocks whose cluster hits could still
  // reach the best while every pose of the block would stand where the sensor saw through:
  // mostly low clusters (things the top of the image cuts off, as a sensor looking steeply down
  // sees them) and clutter near the threshold. Larger blocks keep few common cells (on the
  // real-time protocol's frames, blocks of 4 and 8 steps took 28.7 k bounds a frame to 28.6 k,
  // for more time than they saved). false: theta blocks take the part at single translations
  // only, as before.
  bool theta_block_pair_free_part = true;
  // A block of 2^t headings (t > 0) and 2^L steps is split in theta while the widest arc its
  // template columns sweep over its headings (TemplateRotations::block_extent(t), in lattice
  // steps) is at least theta_split_ratio x 2^L, in translation otherwise; always in theta at
  // single translations. Single headings barely tighten a block's bound while its arc is not
  // several times wider than its side (the arc is a column's at the template's rim; most lie
  // nearer its axis), and each split in theta doubles the bounds: 4 does the least work on the
  // real-time protocol's frames. 0: the rule of theta_split_lead below instead.
  double theta_split_ratio = 4.0;
  // With theta_split_ratio 0: split in theta while t + theta_split_lead >= L (6, with the
  // default max_level: theta blocks only at the top level, as before theta_split_ratio).
  int theta_split_lead = 6;
  // The queue starts with blocks of 2^top_theta_level headings (at most
  // TemplateRotations::kThetaLevels - 1) at every top translation block. Blocks of 2 ..
  // 2^kSweptLevels steps take the swept bound of their headings together
  // (TemplateRotations::SweptBlockGroups), single translations the union of their headings'
  // cells; larger blocks the arc bound (every rotation's columns swept over the block's arc).
  // Theta blocks carry a free-space part at single translations only (theta_block_free_part).
  // 0 starts from single headings (the default before theta_split_ratio, with 4.2x the bounds
  // on the real-time protocol's frames).
  int top_theta_level = 4;
  // A template taller than 64 z cells is searched as the sum of its slabs of 64 cells
  // (TemplateRotations::slabs), each with the cell tables and bounds above; false: with its
  // two-word columns, which take none of them (the column bounds only, as before slabs).
  bool slabs = true;
};

// The global optimum of the score over the whole lattice: every theta (angle_steps of them) x
// every translation in the region above, found by best-first branch and bound. Blocks of
// 2^k x 2^k translations at one theta are bounded with OR-max-filtered occupancy
// (ColumnOccupancy: the correlative scan matching idea applied to voxel columns) and, with
// free-space evidence, AND-min-filtered free space; a block is split only while its bound can
// still beat the best exact value, and single poses are evaluated exactly. The result's value
// equals exhaustive evaluation of the same lattice, and of the poses of that value it is the
// one with the lowest (itheta, ix, iy) (SearchQueue's order), whatever the bounding options.
// The runner-up is the exact best with theta more than 30 degrees from the best (the same rule
// among ties).
class ExactSearch final : public PoseSearch {
 public:
  explicit ExactSearch(ExactSearchOptions options = {}) : options_(options) {}
  SearchResult Search(const SearchProblem& problem) const override;
  // The runner-up's search continues from the optimum's queue (every bound computed for the
  // optimum serves it): the same runner-up as Search's. A search stopped below min_value keeps
  // its queue in `stopped` when given; lowered, it gives what a search down to the lower value
  // gives, bounding only what the first part had not.
  std::unique_ptr<RunnerUpSearch> SearchBest(
      const SearchProblem& problem, SearchResult* result,
      std::unique_ptr<StoppedSearch>* stopped = nullptr) const override;
  double OriginMargin(const TemplateRotations& rotations) const override;
  // Keeps `queues` branch-and-bound queues (at most 16) for the searches to come, each with its
  // memory made and written for `blocks` nodes queued at once and as many deferred: a stream's
  // searches then take no page of memory the process had not, however large the first ones are
  // (a page fault costs microseconds, tens of them in some virtual machines). The queues are
  // shared by every search of the process.
  static void ReserveQueues(int queues, size_t blocks);
  // The cluster's occupancy grid and its free space's, with the levels and extent every given
  // template's search reads (null when the templates' z layouts differ or the grids would not
  // take the aligned layout, whose reads need no scratch space).
  std::shared_ptr<const SearchGrids> MakeGrids(
      const ClusterVoxels& cluster, const ClusterVoxels* free_space,
      const std::vector<const TemplateRotations*>& rotations) const override;

  // The translation region (inclusive lattice indices) that Search covers for this cluster and
  // template; exhaustive checks iterate the same region.
  struct Region {
    int ix_min = 0, ix_max = -1, iy_min = 0, iy_max = -1;
  };
  Region TranslationRegion(const ClusterVoxels& cluster, const TemplateRotations& rotations) const;

 private:
  // Whether the template is searched as the sum of its slabs (ExactSearchOptions::slabs).
  bool BySlabs(const TemplateRotations& rotations) const;
  // The margin of TranslationRegion (metres).
  double Margin(const TemplateRotations& rotations) const;
  // What a search of the cluster with the template reads of the grids.
  struct GridNeeds;
  GridNeeds Needs(const Region& region, const TemplateRotations& rotations) const;
  // MakeGrids for templates searched over the given regions (one each).
  std::shared_ptr<const SearchGrids> MakeGridsIn(
      const ClusterVoxels& cluster, const ClusterVoxels* free_space,
      const std::vector<const TemplateRotations*>& rotations,
      const std::vector<Region>& regions) const;

  ExactSearchOptions options_;
};

}  // namespace hpose

#endif  // HPOSE_CORE_SEARCH_EXACT_SEARCH_H_
