#ifndef HPOSE_CORE_DEPTH_NEIGHBOUR_SAMPLER_H_
#define HPOSE_CORE_DEPTH_NEIGHBOUR_SAMPLER_H_

#include <array>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace hpose {

// Draws random neighbours of a point of a fixed set: points within `radius_m` of it. The points
// are sorted into cubic cells of side radius_m once, so every neighbour of a point lies in the
// 27 cells around its own. A draw picks a point of those cells at random and keeps it when it
// is within the radius (one try in three or so on a plane), so it costs a few lookups where a
// radius search would list hundreds of neighbours. After kMaxTries misses it lists the
// neighbours and picks among them, so a draw fails only when there are too few: every
// neighbour is equally likely either way.
//
// Built for RANSAC's local sampling (the 2nd and 3rd point of a hypothesis near the 1st).
// The points must be finite and outlive the sampler; coordinates beyond +-2^20 cells are
// clamped into the outermost cells, which keeps every neighbour within the 27 cells.
class NeighbourSampler {
 public:
  static constexpr int kMaxTries = 32;

  NeighbourSampler(const std::vector<Eigen::Vector3f>& points, float radius_m);

  // Two distinct points, neither `centre`, within the radius of points[centre] (inclusive), each
  // unordered pair equally likely; false when it has fewer than two such neighbours.
  bool DrawPair(int centre, std::mt19937* rng, int* first, int* second);

  // Every point but `centre` within the radius of points[centre], ascending (the reference of
  // the draws).
  void Neighbours(int centre, std::vector<int>* out) const;

 private:
  // A cell's block: the [begin, end) ranges of sorted_ of the occupied cells among the 27 around
  // it, and their total count.
  struct Block {
    std::vector<std::pair<int, int>> ranges;
    int count = 0;
  };

  const Block& BlockOf(int centre);
  // One draw: a point other than centre and `exclude` within the radius, or -1.
  int DrawOne(int centre, int exclude, std::mt19937* rng);
  bool Near(int centre, int i) const;

  const std::vector<Eigen::Vector3f>& points_;
  float radius2_;
  std::vector<int> sorted_;               // point indices ordered by cell key.
  std::vector<std::uint64_t> cell_keys_;  // the occupied cells' keys, ascending.
  std::vector<int> cell_start_;           // cell k's points: sorted_[cell_start_[k], [k + 1]).
  std::vector<std::int32_t> cell_of_point_;
  std::vector<std::array<std::int32_t, 3>> coords_;  // a cell's integer coordinates.
  std::vector<Block> blocks_;  // per cell, made on first use (count 0 until then).
  std::vector<int> scratch_;
};

}  // namespace hpose

#endif  // HPOSE_CORE_DEPTH_NEIGHBOUR_SAMPLER_H_
