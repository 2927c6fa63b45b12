#include "core/depth/occluded_piece_merge.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace hpose {
namespace {

// A point as the sensor sees it: direction (unit vector), distance and its cluster.
struct Seen {
  Eigen::Vector3f dir;
  float distance;
  int cluster;
};

// Above this many clusters the pairs are not screened (below it the screen costs microseconds).
constexpr int kMaxScreenedClusters = 256;

// Which clusters may take part in a merge, from their boxes alone: piece b behind cluster a
// needs a point p of b and q of a whose directions from the sensor differ by at most the
// neighbour angle at q and whose distances by at most max_depth_gap_m, so
// |p - q| <= |p| |dir p - dir q| + (|p| - |q|) <= (b's farthest distance) x (a's largest
// neighbour angle) + max_depth_gap_m: their boxes grown by that overlap. Clusters in no such
// pair change nothing (the search below finds the same pairs among the others); all are kept
// when there are too many to screen or screen_by_boxes is off.
std::vector<bool> MayMerge(const Eigen::Vector3f& sensor, const OccludedPieceOptions& options,
                           const std::vector<Cluster>& clusters) {
  const int n = static_cast<int>(clusters.size());
  const bool all = !options.screen_by_boxes || n > kMaxScreenedClusters;
  std::vector<bool> involved(n, all);
  if (all) return involved;
  std::vector<Eigen::Vector3d> lo(n), hi(n);
  std::vector<double> nearest(n), farthest(n);
  for (int c = 0; c < n; ++c) {
    const std::vector<Eigen::Vector3f>& points = clusters[c].points;
    if (points.empty()) continue;
    Eigen::Vector3f l = points.front(), h = l;
    for (const Eigen::Vector3f& p : points) {
      l = l.cwiseMin(p);
      h = h.cwiseMax(p);
    }
    lo[c] = (l - sensor).cast<double>();
    hi[c] = (h - sensor).cast<double>();
    const Eigen::Vector3d inside = lo[c].cwiseMax(0.0).cwiseMin(hi[c]);  // the box's nearest.
    nearest[c] = inside.norm();
    farthest[c] = lo[c].cwiseAbs().cwiseMax(hi[c].cwiseAbs()).norm();
  }
  // Float rounding of the search's own tests (directions, distances) is far below this.
  constexpr double kSlack = 1e-3;
  for (int a = 0; a < n; ++a) {
    const size_t a_size = clusters[a].points.size();
    if (a_size == 0) continue;
    const double angle = nearest[a] > 0.0
                             ? std::max(options.max_angle_rad, 2.0 * options.leaf_m / nearest[a])
                             : std::numeric_limits<double>::infinity();
    for (int b = 0; b < n; ++b) {
      const size_t b_size = clusters[b].points.size();
      if (b == a || b_size == 0) continue;
      if (static_cast<double>(b_size) > options.max_point_fraction * a_size) continue;
      const double reach = farthest[b] * angle + options.max_depth_gap_m + kSlack;
      const bool apart =
          ((lo[b] - hi[a]).array() > reach).any() || ((lo[a] - hi[b]).array() > reach).any();
      if (!apart) involved[a] = involved[b] = true;
    }
  }
  return involved;
}

int Find(std::vector<int>* parent, int i) {
  while ((*parent)[i] != i) i = (*parent)[i] = (*parent)[(*parent)[i]];
  return i;
}

}  // namespace

void MergeOccludedPieces(const Eigen::Vector3f& sensor, const OccludedPieceOptions& options,
                         std::vector<Cluster>* clusters) {
  if (!(options.max_depth_gap_m > 0.0) || clusters->size() < 2) return;
  const int n = static_cast<int>(clusters->size());
  const std::vector<bool> involved = MayMerge(sensor, options, *clusters);
  if (std::none_of(involved.begin(), involved.end(), [](bool b) { return b; })) return;
  std::vector<Seen> seen;
  size_t total = 0;
  for (int c = 0; c < n; ++c) total += involved[c] ? (*clusters)[c].points.size() : 0;
  seen.reserve(total);
  float nearest = std::numeric_limits<float>::max();
  // Each involved cluster's lowest and highest point (ground frame), for
  // OccludedPieceOptions::min_lift_m.
  std::vector<float> lowest(n, std::numeric_limits<float>::max());
  std::vector<float> highest(n, std::numeric_limits<float>::lowest());
  for (int c = 0; c < n; ++c) {
    if (!involved[c]) continue;
    for (const Eigen::Vector3f& p : (*clusters)[c].points) {
      lowest[c] = std::min(lowest[c], p.z());
      highest[c] = std::max(highest[c], p.z());
      const Eigen::Vector3f d = p - sensor;
      const float distance = d.norm();
      if (!(distance > 1e-6f)) continue;
      seen.push_back({d / distance, distance, c});
      nearest = std::min(nearest, distance);
    }
  }
  if (seen.empty()) return;
  // Directions binned by their y and z components, in cells of the largest neighbour angle (a
  // dense grid, counting-sorted): two directions less than that angle apart differ by less
  // than a cell in each component, so a point's neighbours lie in the 3 x 3 cells around it.
  // (At least 4 mrad: at most 500 x 500 cells whatever the options.)
  const double cell =
      std::max({options.max_angle_rad, 2.0 * options.leaf_m / static_cast<double>(nearest), 0.004});
  std::vector<int> col(seen.size()), row(seen.size());
  int col_lo = std::numeric_limits<int>::max(), col_hi = std::numeric_limits<int>::min();
  int row_lo = col_lo, row_hi = col_hi;
  for (size_t i = 0; i < seen.size(); ++i) {
    const Eigen::Vector3f& dir = seen[i].dir;
    col[i] = static_cast<int>(std::floor(dir.y() / cell));
    row[i] = static_cast<int>(std::floor(dir.z() / cell));
    col_lo = std::min(col_lo, col[i]);
    col_hi = std::max(col_hi, col[i]);
    row_lo = std::min(row_lo, row[i]);
    row_hi = std::max(row_hi, row[i]);
  }
  const int cols = col_hi - col_lo + 1, rows = row_hi - row_lo + 1;
  std::vector<int> start(static_cast<size_t>(cols) * rows + 1, 0);
  auto bin = [&](int c, int r) { return static_cast<size_t>(r - row_lo) * cols + (c - col_lo); };
  for (size_t i = 0; i < seen.size(); ++i) ++start[bin(col[i], row[i]) + 1];
  for (size_t k = 1; k < start.size(); ++k) start[k] += start[k - 1];
  std::vector<int> sorted(seen.size());
  {
    std::vector<int> next(start.begin(), start.end() - 1);
    for (size_t i = 0; i < seen.size(); ++i)
      sorted[next[bin(col[i], row[i])]++] = static_cast<int>(i);
  }
  size_t largest = 0;
  for (const Cluster& c : *clusters) largest = std::max(largest, c.points.size());
  const bool lift_rule = options.min_lift_m > 0.0;
  const float min_lift = static_cast<float>(options.min_lift_m);
  // Whether `piece` stands where `body` stands and stays in its lower half: an object behind it.
  const auto stands_behind = [&](int piece, int body) {
    return lift_rule && lowest[piece] < lowest[body] + min_lift &&
           highest[piece] < 0.5f * (lowest[body] + highest[body]);
  };
  // Per bin, the one cluster all its points belong to (kEmpty without points, kMixed with
  // several): a point whose 3 x 3 bins hold only its own cluster has no neighbour to test.
  constexpr int kEmpty = -1, kMixed = -2;
  std::vector<int> bin_cluster(static_cast<size_t>(cols) * rows, kEmpty);
  for (size_t i = 0; i < seen.size(); ++i) {
    int& b = bin_cluster[bin(col[i], row[i])];
    b = b == kEmpty || b == seen[i].cluster ? seen[i].cluster : kMixed;
  }

  // hidden_by[b]: the largest cluster that hides piece b, if any.
  std::vector<int> hidden_by(n, -1);
  for (size_t i = 0; i < seen.size(); ++i) {
    const Seen& far = seen[i];
    const size_t far_size = (*clusters)[far.cluster].points.size();
    if (static_cast<double>(far_size) > options.max_point_fraction * largest) continue;
    const int r_lo = std::max(row_lo, row[i] - 1), r_hi = std::min(row_hi, row[i] + 1);
    const int c_lo = std::max(col_lo, col[i] - 1), c_hi = std::min(col_hi, col[i] + 1);
    bool others = false;
    for (int r = r_lo; r <= r_hi && !others; ++r) {
      for (int c = c_lo; c <= c_hi; ++c) {
        const int b = bin_cluster[bin(c, r)];
        if (b != kEmpty && b != far.cluster) {
          others = true;
          break;
        }
      }
    }
    if (!others) continue;
    for (int r = r_lo; r <= r_hi; ++r) {
      for (int c = c_lo; c <= c_hi; ++c) {
        const size_t k = bin(c, r);
        for (int s = start[k]; s < start[k + 1]; ++s) {
          const Seen& near = seen[sorted[s]];
          if (near.cluster == far.cluster) continue;
          const size_t near_size = (*clusters)[near.cluster].points.size();
          if (static_cast<double>(far_size) > options.max_point_fraction * near_size) continue;
          if (stands_behind(far.cluster, near.cluster)) continue;
          const float step = far.distance - near.distance;
          if (!(step > 0.0f) || step > options.max_depth_gap_m) continue;
          const double limit =
              std::max(options.max_angle_rad, 2.0 * options.leaf_m / near.distance);
          if ((far.dir - near.dir).norm() > limit) continue;
          int& best = hidden_by[far.cluster];
          // The largest hider, the first cluster among equals (whatever the bins' order).
          if (best < 0 || (*clusters)[best].points.size() < near_size ||
              ((*clusters)[best].points.size() == near_size && near.cluster < best)) {
            best = near.cluster;
          }
        }
      }
    }
  }
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  bool any = false;
  for (int c = 0; c < n; ++c) {
    if (hidden_by[c] < 0) continue;
    const int from = Find(&parent, c), into = Find(&parent, hidden_by[c]);
    if (from == into) continue;
    // The larger cluster's root stays (a piece never absorbs its hider).
    if ((*clusters)[from].points.size() > (*clusters)[into].points.size()) {
      parent[into] = from;
    } else {
      parent[from] = into;
    }
    any = true;
  }
  if (!any) return;
  std::vector<Cluster> merged;
  std::vector<int> slot(n, -1);
  for (int c = 0; c < n; ++c) {
    const int root = Find(&parent, c);
    if (root == c) {
      slot[c] = static_cast<int>(merged.size());
      merged.push_back(std::move((*clusters)[c]));
    }
  }
  for (int c = 0; c < n; ++c) {
    const int root = Find(&parent, c);
    if (root == c) continue;
    std::vector<Eigen::Vector3f>& into = merged[slot[root]].points;
    into.insert(into.end(), (*clusters)[c].points.begin(), (*clusters)[c].points.end());
  }
  clusters->swap(merged);
}

}  // namespace hpose
