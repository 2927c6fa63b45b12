#include "core/depth/voxel_downsample.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>

#include "core/depth/point_lanes.h"

namespace hpose {
namespace {

// 21 bits per axis: +-2^20 voxels, i.e. +-8 km at 8 mm; coordinates beyond are clamped.
constexpr std::int64_t kAxisLimit = (1 << 20) - 1;
constexpr std::uint64_t kEmpty = ~std::uint64_t{0};

// floor(x) for |x| <= kAxisLimit without a libm call (x86-64's baseline has no SSE4.1 round).
std::int64_t FloorToInt(float x) {
  const std::int64_t truncated = static_cast<std::int64_t>(x);
  return truncated - (static_cast<float>(truncated) > x ? 1 : 0);
}

std::uint64_t PackKey(const Eigen::Vector3f& p, float inv_leaf) {
  // Clamping before flooring gives floor-then-clamp's result: the limit is an integer.
  const float limit = static_cast<float>(kAxisLimit);
  std::uint64_t key = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const std::int64_t cell = FloorToInt(std::clamp(p[axis] * inv_leaf, -limit, limit));
    key = (key << 21) | static_cast<std::uint64_t>(cell + kAxisLimit);
  }
  return key;
}

// PackKey of every point into keys[0 .. n).
void PackKeysScalar(const Eigen::Vector3f* points, size_t n, float inv_leaf, std::uint64_t* keys) {
  for (size_t i = 0; i < n; ++i) keys[i] = PackKey(points[i], inv_leaf);
}

#ifdef HPOSE_POINT_LANES
// PackKeysScalar sixteen points a step: per axis the same product, clamped (for finite values
// min(max(v, -limit), limit) is std::clamp) and floored (exactly, by rounding toward -inf; the
// clamped value fits an int32), then the three cells packed in 64-bit lanes, eight at a time.
// Masked forms of the conversions: the unmasked ones start from an undefined register, which
// GCC 12 reports as uninitialised.
[[gnu::target("avx2,avx512f")]] void PackKeysAvx512(const Eigen::Vector3f* points, size_t n,
                                                    float inv_leaf, std::uint64_t* keys) {
  const PointDeinterleaver lanes;
  const __m512 inv = _mm512_set1_ps(inv_leaf);
  const float limit_f = static_cast<float>(kAxisLimit);
  const __m512 hi = _mm512_set1_ps(limit_f), lo = _mm512_set1_ps(-limit_f);
  const __m512i offset = _mm512_set1_epi32(static_cast<int>(kAxisLimit));
  size_t i = 0;
  for (; i + 16 <= n; i += 16) {
    const PointLanes p = lanes.Load(points[i].data());
    alignas(64) std::int32_t cells[3][16];
    const __m512 axes[3] = {p.x, p.y, p.z};
    for (int a = 0; a < 3; ++a) {
      const __m512 v = _mm512_maskz_min_ps(
          0xFFFF, _mm512_maskz_max_ps(0xFFFF, _mm512_mul_ps(axes[a], inv), lo), hi);
      const __m512 floored =
          _mm512_maskz_roundscale_ps(0xFFFF, v, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
      _mm512_store_si512(cells[a],
                         _mm512_add_epi32(_mm512_maskz_cvttps_epi32(0xFFFF, floored), offset));
    }
    for (int half = 0; half < 2; ++half) {
      __m512i key = _mm512_setzero_si512();
      for (int a = 0; a < 3; ++a) {
        const __m512i cell = _mm512_maskz_cvtepu32_epi64(
            0xFF, _mm256_load_si256(reinterpret_cast<const __m256i*>(cells[a] + 8 * half)));
        key = _mm512_or_si512(_mm512_maskz_slli_epi64(0xFF, key, 21), cell);
      }
      _mm512_storeu_si512(keys + i + 8 * half, key);
    }
  }
  PackKeysScalar(points + i, n - i, inv_leaf, keys + i);
}

// PackKeysScalar eight points a step with AVX2: the same product, clamp and floor per axis
// (_mm256_floor_ps rounds toward -inf exactly), and the cells packed four keys at a time.
[[gnu::target("avx2")]] void PackKeysAvx2(const Eigen::Vector3f* points, size_t n, float inv_leaf,
                                          std::uint64_t* keys) {
  const PointShuffles8 shuffles;
  const __m256 inv = _mm256_set1_ps(inv_leaf);
  const float limit_f = static_cast<float>(kAxisLimit);
  const __m256 hi = _mm256_set1_ps(limit_f), lo = _mm256_set1_ps(-limit_f);
  const __m256i offset = _mm256_set1_epi32(static_cast<int>(kAxisLimit));
  size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    const PointLanes8 p = shuffles.Load(points[i].data());
    const __m256 axes[3] = {p.x, p.y, p.z};
    __m256i cells[3];
    for (int a = 0; a < 3; ++a) {
      const __m256 v = _mm256_min_ps(_mm256_max_ps(_mm256_mul_ps(axes[a], inv), lo), hi);
      cells[a] = _mm256_add_epi32(_mm256_cvttps_epi32(_mm256_floor_ps(v)), offset);
    }
    for (int half = 0; half < 2; ++half) {
      __m256i key = _mm256_setzero_si256();
      for (int a = 0; a < 3; ++a) {
        const __m128i four =
            half == 0 ? _mm256_castsi256_si128(cells[a]) : _mm256_extracti128_si256(cells[a], 1);
        key = _mm256_or_si256(_mm256_slli_epi64(key, 21), _mm256_cvtepu32_epi64(four));
      }
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(keys + i + 4 * half), key);
    }
  }
  PackKeysScalar(points + i, n - i, inv_leaf, keys + i);
}

#else
constexpr auto* PackKeysAvx512 = &PackKeysScalar;
constexpr auto* PackKeysAvx2 = &PackKeysScalar;
#endif

std::uint64_t Mix(std::uint64_t key) {
  key ^= key >> 33;
  key *= 0xff51afd7ed558ccdULL;
  key ^= key >> 33;
  return key;
}

}  // namespace

void PackVoxelKeys(const Eigen::Vector3f* points, size_t n, float inv_leaf, std::uint64_t* keys) {
  (PointLanesAvailable()    ? PackKeysAvx512
   : PointLanes8Available() ? PackKeysAvx2
                            : PackKeysScalar)(points, n, inv_leaf, keys);
}

void PackVoxelKeysScalar(const Eigen::Vector3f* points, size_t n, float inv_leaf,
                         std::uint64_t* keys) {
  PackKeysScalar(points, n, inv_leaf, keys);
}

void PackVoxelKeysAvx2(const Eigen::Vector3f* points, size_t n, float inv_leaf,
                       std::uint64_t* keys) {
  assert(VoxelKeysAvx2Available());
  PackKeysAvx2(points, n, inv_leaf, keys);
}

bool VoxelKeysAvx2Available() { return PointLanes8Available(); }

void VoxelDownsample(const std::vector<Eigen::Vector3f>& points, float leaf_m,
                     std::vector<Eigen::Vector3f>* centroids, std::vector<int>* voxel_of_point) {
  assert(leaf_m > 0.0f);
  assert(centroids != nullptr);
  centroids->clear();
  if (voxel_of_point != nullptr) voxel_of_point->resize(points.size());
  if (points.empty()) return;

  // Open addressing, at most half full: the keys in one array (what a probe reads) and each
  // key's voxel in another (read once the key matches). Sized for a quarter of the points as
  // voxels (depth clouds have several points per voxel) and doubled when that is exceeded: a
  // table sized for every point would not fit in the cache for a 640x480 frame and would cost
  // more than it saves.
  size_t capacity = 64;
  while (capacity < points.size() / 2) capacity <<= 1;
  size_t mask = capacity - 1;
  std::vector<std::uint64_t> table(capacity, kEmpty);
  std::vector<int> table_voxel(capacity);
  std::vector<std::uint64_t> keys;  // of each voxel, to rehash.
  std::vector<int> counts;
  counts.reserve(points.size() / 4 + 16);
  keys.reserve(points.size() / 4 + 16);
  centroids->reserve(points.size() / 4 + 16);
  auto find_slot = [&](std::uint64_t key) {
    size_t slot = Mix(key) & mask;
    while (table[slot] != kEmpty && table[slot] != key) slot = (slot + 1) & mask;
    return slot;
  };

  const float inv_leaf = 1.0f / leaf_m;
  // Every point's key first, so that the loop below can ask for the slot of a key kAhead points
  // on while it works on this one: the probes of a 640x480 frame's table miss the cache.
  std::vector<std::uint64_t> point_keys(points.size());
  PackVoxelKeys(points.data(), points.size(), inv_leaf, point_keys.data());
  constexpr size_t kAhead = 16;
  // Depth-camera clouds come in scan order, so consecutive points often share a voxel: the
  // last key is remembered to skip the table lookup.
  std::uint64_t last_key = kEmpty;
  int last_voxel = -1;
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    const std::uint64_t key = point_keys[i];
    if (i + kAhead < points.size()) {
      __builtin_prefetch(&table[Mix(point_keys[i + kAhead]) & mask]);
    }
    int voxel = last_voxel;
    if (key != last_key) {
      const size_t slot = find_slot(key);
      if (table[slot] == key) {
        voxel = table_voxel[slot];
      } else {
        voxel = static_cast<int>(centroids->size());
        table[slot] = key;
        table_voxel[slot] = voxel;
        centroids->push_back(Eigen::Vector3f::Zero());
        counts.push_back(0);
        keys.push_back(key);
        if (2 * keys.size() > capacity) {
          capacity <<= 1;
          mask = capacity - 1;
          table.assign(capacity, kEmpty);
          table_voxel.resize(capacity);
          for (size_t v = 0; v < keys.size(); ++v) {
            const size_t to = find_slot(keys[v]);
            table[to] = keys[v];
            table_voxel[to] = static_cast<int>(v);
          }
        }
      }
      last_key = key;
      last_voxel = voxel;
    }
    (*centroids)[voxel] += p;
    ++counts[voxel];
    if (voxel_of_point != nullptr) (*voxel_of_point)[i] = voxel;
  }
  for (size_t v = 0; v < centroids->size(); ++v) {
    (*centroids)[v] /= static_cast<float>(counts[v]);
  }
}

}  // namespace hpose
