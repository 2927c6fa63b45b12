#include "core/depth/grid_euclidean_clusters.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <utility>

namespace hpose {
namespace {

int Find(std::vector<int>* parent, int i) {
  std::vector<int>& p = *parent;
  while (p[i] != i) {
    p[i] = p[p[i]];
    i = p[i];
  }
  return i;
}

// Squared distance as FLANN's L2_Simple computes it: float, x then y then z.
inline float SquaredDistance(const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
  float d = 0.0f;
  float t = a.x() - b.x();
  d += t * t;
  t = a.y() - b.y();
  d += t * t;
  t = a.z() - b.z();
  d += t * t;
  return d;
}

constexpr int kKeyBits = 21;
constexpr std::int64_t kKeyRange = std::int64_t{1} << kKeyBits;

}  // namespace

std::vector<int> GridEuclideanClusterLabels(const std::vector<Eigen::Vector3f>& points,
                                            double tolerance_m, int* cluster_count) {
  assert(tolerance_m > 0.0 && cluster_count != nullptr);
  const int n = static_cast<int>(points.size());
  std::vector<int> labels(points.size(), -1);
  *cluster_count = 0;
  if (n == 0) return labels;

  // Buckets slightly larger than the tolerance: neighbours are then always in the same or an
  // adjacent bucket, whatever the rounding of the division.
  const double cell = tolerance_m * (1.0 + 1e-6);
  std::vector<Eigen::Matrix<std::int64_t, 3, 1>> key(points.size());
  for (int i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) {
      // floor() without a libm call: truncate, then step down for negative fractions.
      const double q = static_cast<double>(points[i][a]) / cell;
      const std::int64_t truncated = static_cast<std::int64_t>(q);
      key[i][a] = truncated - (static_cast<double>(truncated) > q ? 1 : 0);
    }
  }
  Eigen::Matrix<std::int64_t, 3, 1> lo = key[0], hi = key[0];
  for (int i = 1; i < n; ++i) {
    lo = lo.cwiseMin(key[i]);
    hi = hi.cwiseMax(key[i]);
  }
  // Bucket keys packed with one empty bucket of margin on every side.
  const bool packable = ((hi - lo).array() + 2 < kKeyRange - 1).all();
  std::vector<int> parent(points.size());
  std::iota(parent.begin(), parent.end(), 0);
  const float tol2 = static_cast<float>(tolerance_m * tolerance_m);
  // Joins the components of i and j when they are within the tolerance; true when they are
  // (whether or not they were joined already).
  auto unite = [&](int i, int j) {
    if (SquaredDistance(points[i], points[j]) >= tol2) return false;
    int ri = Find(&parent, i), rj = Find(&parent, j);
    if (ri == rj) return true;
    if (ri > rj) std::swap(ri, rj);
    parent[rj] = ri;
    return true;
  };
  if (!packable) {
    // Absurd extent for the tolerance: compare every pair (correct, slow, never hit in practice).
    for (int i = 0; i < n; ++i) {
      for (int j = i + 1; j < n; ++j) unite(i, j);
    }
  } else {
    auto pack = [&](std::int64_t x, std::int64_t y, std::int64_t z) {
      return static_cast<std::uint64_t>(((x - lo.x() + 1) << (2 * kKeyBits)) |
                                        ((y - lo.y() + 1) << kKeyBits) | (z - lo.z() + 1));
    };
    std::vector<std::pair<std::uint64_t, int>> order(points.size());
    for (int i = 0; i < n; ++i) order[i] = {pack(key[i].x(), key[i].y(), key[i].z()), i};
    std::sort(order.begin(), order.end());
    // Runs of equal keys: bucket b holds order[start[b] .. start[b + 1]).
    std::vector<std::uint64_t> bucket_key;
    std::vector<int> start;
    for (int k = 0; k < n; ++k) {
      if (k == 0 || order[k].first != order[k - 1].first) {
        bucket_key.push_back(order[k].first);
        start.push_back(k);
      }
    }
    start.push_back(n);
    const int buckets = static_cast<int>(bucket_key.size());
    // The root shared by every point of bucket b, or -1 when they lie in several components.
    auto common_root = [&](int b) {
      const int root = Find(&parent, order[start[b]].second);
      for (int s = start[b] + 1; s < start[b + 1]; ++s) {
        if (Find(&parent, order[s].second) != root) return -1;
      }
      return root;
    };
    const std::uint64_t one_y = std::uint64_t{1} << kKeyBits;
    const std::uint64_t one_x = std::uint64_t{1} << (2 * kKeyBits);
    for (int b = 0; b < buckets; ++b) {
      // Pairs inside the bucket.
      for (int s = start[b]; s < start[b + 1]; ++s) {
        for (int t = s + 1; t < start[b + 1]; ++t) unite(order[s].second, order[t].second);
      }
      // The 13 neighbour buckets after this one in key order: (0, 0, +1), then the columns
      // (0, +1), (+1, -1), (+1, 0), (+1, +1) at z - 1 .. z + 1, each a contiguous key range.
      const std::uint64_t k = bucket_key[b];
      const std::uint64_t ranges[5][2] = {
          {k + 1, k + 1},
          {k + one_y - 1, k + one_y + 1},
          {k + one_x - one_y - 1, k + one_x - one_y + 1},
          {k + one_x - 1, k + one_x + 1},
          {k + one_x + one_y - 1, k + one_x + one_y + 1},
      };
      for (const auto& r : ranges) {
        auto it = std::lower_bound(bucket_key.begin() + b + 1, bucket_key.end(), r[0]);
        for (; it != bucket_key.end() && *it <= r[1]; ++it) {
          const int c = static_cast<int>(it - bucket_key.begin());
          // Two buckets each already inside one component: one close pair joins them and
          // nothing else can change, so the pair scan stops there (or is skipped when they are
          // already one component). Only the union-find changes, not the components.
          const int root_b = common_root(b);
          const int root_c = root_b >= 0 ? common_root(c) : -1;
          if (root_b >= 0 && root_b == root_c) continue;
          const bool stop_at_first = root_b >= 0 && root_c >= 0;
          bool joined = false;
          for (int s = start[b]; s < start[b + 1] && !joined; ++s) {
            for (int t = start[c]; t < start[c + 1]; ++t) {
              if (unite(order[s].second, order[t].second) && stop_at_first) {
                joined = true;
                break;
              }
            }
          }
        }
      }
    }
  }
  // Label in order of each cluster's lowest index (the root is the lowest index).
  for (int i = 0; i < n; ++i) {
    const int r = Find(&parent, i);
    if (r == i) {
      labels[i] = (*cluster_count)++;
    } else {
      labels[i] = labels[r];
    }
  }
  return labels;
}

}  // namespace hpose
