#include "core/depth/grid_euclidean_clusters.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <utility>

#include "core/depth/point_lanes.h"

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

// Sorts (packed bucket key, point index) pairs, given in index order, by key and then index: the
// order std::sort gives them. `span` bounds each axis' field of the key (x in the high bits, z in
// the low; every field < its span). Where every span is small, three stable counting passes, z
// then y then x (a 640x480 frame's buckets sort in a sixth of std::sort's time); std::sort
// otherwise.
void SortByBucket(const Eigen::Matrix<std::int64_t, 3, 1>& span,
                  std::vector<std::pair<std::uint64_t, int>>* order) {
  constexpr std::int64_t kMaxCountingSpan = 1 << 16;
  if (order->size() < 256 || (span.array() > kMaxCountingSpan).any()) {
    std::sort(order->begin(), order->end());
    return;
  }
  constexpr std::uint64_t kFieldMask = (std::uint64_t{1} << kKeyBits) - 1;
  std::vector<std::pair<std::uint64_t, int>> other(order->size());
  std::vector<int> start;
  for (int axis = 2; axis >= 0; --axis) {
    const int shift = (2 - axis) * kKeyBits;
    start.assign(static_cast<size_t>(span[axis]) + 1, 0);
    for (const auto& e : *order) ++start[((e.first >> shift) & kFieldMask) + 1];
    for (size_t v = 1; v < start.size(); ++v) start[v] += start[v - 1];
    for (const auto& e : *order) other[start[(e.first >> shift) & kFieldMask]++] = e;
    order->swap(other);
  }
}

// Points of the buckets in bucket order, as three arrays (what the distance tests read).
struct Lanes {
  const float* x;
  const float* y;
  const float* z;
};

// Bit k set: point t0 + k (k < count <= 16) of `lanes` lies within the tolerance of `p`, by
// SquaredDistance's test (not >= tol2).
std::uint32_t CloseMaskScalar(const Lanes& lanes, int t0, int count, const Eigen::Vector3f& p,
                              float tol2) {
  std::uint32_t mask = 0;
  for (int k = 0; k < count; ++k) {
    const int t = t0 + k;
    const Eigen::Vector3f q(lanes.x[t], lanes.y[t], lanes.z[t]);
    if (!(SquaredDistance(p, q) >= tol2)) mask |= std::uint32_t{1} << k;
  }
  return mask;
}

#ifdef HPOSE_POINT_LANES
// (v - a[k])^2 of the lanes in `valid`, each operation rounded on its own (never fused).
[[gnu::target("avx512f")]] inline __m512 SquaredOffsets(const float* a, __mmask16 valid, float v) {
  const __m512 t = rounded::Sub(_mm512_set1_ps(v), _mm512_maskz_loadu_ps(valid, a));
  return rounded::Mul(t, t);
}

// The same sixteen points at a time: the same products and sums in the same order.
[[gnu::target("avx512f")]] std::uint32_t CloseMaskAvx512(const Lanes& lanes, int t0, int count,
                                                         const Eigen::Vector3f& p, float tol2) {
  const __mmask16 valid = static_cast<__mmask16>((std::uint32_t{1} << count) - 1);
  const __m512 dx = SquaredOffsets(lanes.x + t0, valid, p.x());
  const __m512 dy = SquaredOffsets(lanes.y + t0, valid, p.y());
  const __m512 dz = SquaredOffsets(lanes.z + t0, valid, p.z());
  const __m512 d = rounded::Add(rounded::Add(dx, dy), dz);
  return _mm512_mask_cmp_ps_mask(valid, d, _mm512_set1_ps(tol2), _CMP_NGE_UQ);
}

// With AVX2: the same sixteen points as two vectors of eight, by the same operations (the
// target has no fused multiply-add), lanes at and past `count` read as 0 and then cut.
[[gnu::target("avx2")]] inline __m256 SquaredOffsets8(const float* a, __m256i valid, float v) {
  const __m256 t = _mm256_sub_ps(_mm256_set1_ps(v), _mm256_maskload_ps(a, valid));
  return _mm256_mul_ps(t, t);
}

[[gnu::target("avx2")]] std::uint32_t CloseMaskAvx2(const Lanes& lanes, int t0, int count,
                                                    const Eigen::Vector3f& p, float tol2) {
  const __m256i iota = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256 limit = _mm256_set1_ps(tol2);
  std::uint32_t mask = 0;
  for (int h = 0; h < count; h += 8) {
    const __m256i valid = _mm256_cmpgt_epi32(_mm256_set1_epi32(count - h), iota);
    const __m256 dx = SquaredOffsets8(lanes.x + t0 + h, valid, p.x());
    const __m256 dy = SquaredOffsets8(lanes.y + t0 + h, valid, p.y());
    const __m256 dz = SquaredOffsets8(lanes.z + t0 + h, valid, p.z());
    const __m256 d = _mm256_add_ps(_mm256_add_ps(dx, dy), dz);
    const __m256 close =
        _mm256_and_ps(_mm256_cmp_ps(d, limit, _CMP_NGE_UQ), _mm256_castsi256_ps(valid));
    mask |= static_cast<std::uint32_t>(_mm256_movemask_ps(close)) << h;
  }
  return mask;
}
#else
constexpr auto* CloseMaskAvx512 = &CloseMaskScalar;
constexpr auto* CloseMaskAvx2 = &CloseMaskScalar;
#endif

// GridEuclideanClusterLabels with the distance tests of CloseMask (one bucket's point against up
// to sixteen of another's).
template <std::uint32_t (*CloseMask)(const Lanes&, int, int, const Eigen::Vector3f&, float)>
std::vector<int> Labels(const std::vector<Eigen::Vector3f>& points, double tolerance_m,
                        int* cluster_count) {
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
  // Joins the components of points i and j (the lower index becomes the root).
  auto join = [&](int i, int j) {
    int ri = Find(&parent, i), rj = Find(&parent, j);
    if (ri == rj) return;
    if (ri > rj) std::swap(ri, rj);
    parent[rj] = ri;
  };
  if (!packable) {
    // Absurd extent for the tolerance: compare every pair (correct, slow, never hit in practice).
    for (int i = 0; i < n; ++i) {
      for (int j = i + 1; j < n; ++j) {
        if (!(SquaredDistance(points[i], points[j]) >= tol2)) join(i, j);
      }
    }
  } else {
    auto pack = [&](std::int64_t x, std::int64_t y, std::int64_t z) {
      return static_cast<std::uint64_t>(((x - lo.x() + 1) << (2 * kKeyBits)) |
                                        ((y - lo.y() + 1) << kKeyBits) | (z - lo.z() + 1));
    };
    std::vector<std::pair<std::uint64_t, int>> order(points.size());
    for (int i = 0; i < n; ++i) order[i] = {pack(key[i].x(), key[i].y(), key[i].z()), i};
    SortByBucket(((hi - lo).array() + 3).matrix(), &order);
    // Runs of equal keys: bucket b holds sorted points start[b] .. start[b + 1]; sorted point s
    // is points[index[s]], its coordinates (xs, ys, zs)[s].
    std::vector<std::uint64_t> bucket_key;
    std::vector<int> start;
    std::vector<int> index(n);
    std::vector<float> xs(n), ys(n), zs(n);
    for (int k = 0; k < n; ++k) {
      if (k == 0 || order[k].first != order[k - 1].first) {
        bucket_key.push_back(order[k].first);
        start.push_back(k);
      }
      const int i = order[k].second;
      index[k] = i;
      xs[k] = points[i].x();
      ys[k] = points[i].y();
      zs[k] = points[i].z();
    }
    start.push_back(n);
    const Lanes lanes{xs.data(), ys.data(), zs.data()};
    const int buckets = static_cast<int>(bucket_key.size());
    // The root shared by every point of bucket b, or -1 when they lie in several components.
    // A bucket found in one component stays in one (components only merge): `single` remembers
    // it, and its root is then its first point's.
    std::vector<char> single(bucket_key.size(), 0);
    auto common_root = [&](int b) {
      const int root = Find(&parent, index[start[b]]);
      if (single[b]) return root;
      for (int s = start[b] + 1; s < start[b + 1]; ++s) {
        if (Find(&parent, index[s]) != root) return -1;
      }
      single[b] = 1;
      return root;
    };
    // Joins sorted point s with every point of t0 .. t1 within the tolerance, or with the first
    // one only when `first_only`; true when any was.
    auto join_close = [&](int s, int t0, int t1, bool first_only) {
      const Eigen::Vector3f p(xs[s], ys[s], zs[s]);
      int root = -1;  // of s, once a close point is found.
      for (int t = t0; t < t1; t += 16) {
        std::uint32_t mask = CloseMask(lanes, t, std::min(16, t1 - t), p, tol2);
        for (; mask != 0; mask &= mask - 1) {
          if (root < 0) root = Find(&parent, index[s]);
          const int other = Find(&parent, index[t + __builtin_ctz(mask)]);
          if (other != root) {  // the lower index becomes the root.
            parent[std::max(root, other)] = std::min(root, other);
            root = std::min(root, other);
          }
          if (first_only) return true;
        }
      }
      return root >= 0;
    };
    const std::uint64_t one_y = std::uint64_t{1} << kKeyBits;
    const std::uint64_t one_x = std::uint64_t{1} << (2 * kKeyBits);
    // Pairs inside each bucket first: most buckets are then one component, and between two
    // such the scan stops at the first close pair.
    for (int b = 0; b < buckets; ++b) {
      for (int s = start[b]; s < start[b + 1]; ++s) join_close(s, s + 1, start[b + 1], false);
    }
    int cursor[5] = {0, 0, 0, 0, 0};
    for (int b = 0; b < buckets; ++b) {
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
      for (int q = 0; q < 5; ++q) {
        // The first bucket at or after the range's start: ranges move forward with b.
        int& c0 = cursor[q];
        c0 = std::max(c0, b + 1);
        while (c0 < buckets && bucket_key[c0] < ranges[q][0]) ++c0;
        for (int c = c0; c < buckets && bucket_key[c] <= ranges[q][1]; ++c) {
          // Two buckets each already inside one component: one close pair joins them and
          // nothing else can change, so the pair scan stops there (or is skipped when they are
          // already one component). Only the union-find changes, not the components.
          const int root_b = common_root(b);
          const int root_c = root_b >= 0 ? common_root(c) : -1;
          if (root_b >= 0 && root_b == root_c) continue;
          const bool first_only = root_b >= 0 && root_c >= 0;
          for (int s = start[b]; s < start[b + 1]; ++s) {
            if (join_close(s, start[c], start[c + 1], first_only) && first_only) break;
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

}  // namespace

bool GridEuclideanClustersAvx2Available() { return PointLanes8Available(); }

std::vector<int> GridEuclideanClusterLabels(const std::vector<Eigen::Vector3f>& points,
                                            double tolerance_m, int* cluster_count) {
  if (PointLanesAvailable()) return Labels<CloseMaskAvx512>(points, tolerance_m, cluster_count);
  if (PointLanes8Available()) return Labels<CloseMaskAvx2>(points, tolerance_m, cluster_count);
  return Labels<CloseMaskScalar>(points, tolerance_m, cluster_count);
}

std::vector<int> GridEuclideanClusterLabelsAvx2(const std::vector<Eigen::Vector3f>& points,
                                                double tolerance_m, int* cluster_count) {
  assert(GridEuclideanClustersAvx2Available());
  return Labels<CloseMaskAvx2>(points, tolerance_m, cluster_count);
}

std::vector<int> GridEuclideanClusterLabelsScalar(const std::vector<Eigen::Vector3f>& points,
                                                  double tolerance_m, int* cluster_count) {
  return Labels<CloseMaskScalar>(points, tolerance_m, cluster_count);
}

}  // namespace hpose
