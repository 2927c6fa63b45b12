#include "core/depth/occluded_piece_merge.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
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

std::int64_t CellKey(int a, int b) {
  return (static_cast<std::int64_t>(a) << 32) ^ static_cast<std::uint32_t>(b);
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
  std::vector<Seen> seen;
  float nearest = std::numeric_limits<float>::max();
  for (int c = 0; c < n; ++c) {
    for (const Eigen::Vector3f& p : (*clusters)[c].points) {
      const Eigen::Vector3f d = p - sensor;
      const float distance = d.norm();
      if (!(distance > 1e-6f)) continue;
      seen.push_back({d / distance, distance, c});
      nearest = std::min(nearest, distance);
    }
  }
  if (seen.empty()) return;
  // Directions binned by bearing and elevation, in cells of the largest neighbour angle: a
  // point's neighbours lie in its own or the eight surrounding cells.
  const double cell =
      std::max(options.max_angle_rad, 2.0 * options.leaf_m / static_cast<double>(nearest));
  std::vector<std::pair<std::int64_t, int>> keyed(seen.size());
  auto cell_of = [&](const Eigen::Vector3f& dir, int* a, int* b) {
    *a = static_cast<int>(std::floor(std::atan2(dir.y(), dir.x()) / cell));
    *b = static_cast<int>(std::floor(std::asin(std::clamp(dir.z(), -1.0f, 1.0f)) / cell));
  };
  for (size_t i = 0; i < seen.size(); ++i) {
    int a = 0, b = 0;
    cell_of(seen[i].dir, &a, &b);
    keyed[i] = {CellKey(a, b), static_cast<int>(i)};
  }
  std::sort(keyed.begin(), keyed.end());

  // hidden_by[b]: the largest cluster that hides piece b, if any.
  std::vector<int> hidden_by(n, -1);
  for (size_t i = 0; i < seen.size(); ++i) {
    const Seen& far = seen[i];
    const size_t far_size = (*clusters)[far.cluster].points.size();
    int a = 0, b = 0;
    cell_of(far.dir, &a, &b);
    for (int da = -1; da <= 1; ++da) {
      for (int db = -1; db <= 1; ++db) {
        const std::int64_t key = CellKey(a + da, b + db);
        auto it = std::lower_bound(keyed.begin(), keyed.end(), std::make_pair(key, -1));
        for (; it != keyed.end() && it->first == key; ++it) {
          const Seen& near = seen[it->second];
          if (near.cluster == far.cluster) continue;
          const size_t near_size = (*clusters)[near.cluster].points.size();
          if (static_cast<double>(far_size) > options.max_point_fraction * near_size) continue;
          const float step = far.distance - near.distance;
          if (!(step > 0.0f) || step > options.max_depth_gap_m) continue;
          const double limit =
              std::max(options.max_angle_rad, 2.0 * options.leaf_m / near.distance);
          if ((far.dir - near.dir).norm() > limit) continue;
          int& best = hidden_by[far.cluster];
          if (best < 0 || (*clusters)[best].points.size() < near_size) best = near.cluster;
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
