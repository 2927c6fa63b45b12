#include "core/depth/voxel_downsample.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <vector>

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

// VoxelDownsample's working arrays, kept by each thread between calls.
struct VoxelScratch {
  struct Slot {
    std::uint64_t key;  // kEmpty when free.
    std::int32_t voxel;
  };
  struct Sum {
    float x, y, z;
    std::int32_t count;
  };
  std::vector<std::uint64_t> keys;           // per point, then per run.
  std::vector<std::int32_t> run_of;          // per point.
  std::vector<Slot> table;                   // empty between calls.
  std::vector<std::int32_t> run_voxel;       // per run.
  std::vector<std::uint32_t> slot_of_voxel;  // room for a slot per run: those a call filled.
  std::vector<Sum> sums;                     // per voxel.
};

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
  const size_t n = points.size();
  // The working arrays of a 640x480 frame take megabytes (about 7 MB for a room's 133 k band
  // points, at most about 28 MB were all 307 200 points in the band): allocated anew each frame
  // they would be faulted in (and zeroed) by the kernel each time, which costs more than the
  // work. Each thread keeps its own, grown as needed (never shrunk); the hash table is left
  // empty after every call.
  thread_local VoxelScratch scratch;
  scratch.keys.resize(n);
  scratch.run_of.resize(n);
  // The loops below go through plain pointers taken once: through the thread-local vectors the
  // compiler would fetch the thread's block and each vector's data again at every step.
  std::uint64_t* const keys = scratch.keys.data();
  std::int32_t* const run_of = scratch.run_of.data();

  // 1. Every point's key.
  PackVoxelKeys(points.data(), n, 1.0f / leaf_m, keys);

  // 2. Runs of consecutive points with one key (a depth camera's cloud comes in scan order, so
  // neighbouring points often share a voxel): point i lies in run run_of[i], and keys[r] becomes
  // run r's key (r <= i: written after it is read). Branch-free: whether a run ends is as good as
  // random on a far scene.
  size_t last = 0;
  run_of[0] = 0;
  std::uint64_t previous = keys[0];
  for (size_t i = 1; i < n; ++i) {
    const std::uint64_t key = keys[i];
    last += key != previous ? 1 : 0;
    keys[last] = key;
    run_of[i] = static_cast<std::int32_t>(last);
    previous = key;
  }
  const size_t runs = last + 1;

  // 3. Each run's voxel, numbered as first met, from a hash table of the keys (open addressing,
  // a slot holding its key and voxel: one cache line a probe). At least twice the runs, so at
  // most half full whatever the voxels (no rehash); the probe for a run kAhead runs on is asked
  // for early, as a 640x480 frame's table is larger than the cache. Nothing below allocates (or
  // throws) between filling a slot and recording it: the table must be left empty for the next
  // call.
  size_t capacity = 64;
  while (capacity < 2 * runs) capacity <<= 1;
  const size_t mask = capacity - 1;
  if (scratch.table.size() < capacity)
    scratch.table.assign(capacity, VoxelScratch::Slot{kEmpty, 0});
  scratch.run_voxel.resize(runs);
  scratch.slot_of_voxel.resize(std::max(scratch.slot_of_voxel.size(), runs));
  VoxelScratch::Slot* const table = scratch.table.data();
  std::int32_t* const run_voxel = scratch.run_voxel.data();
  std::uint32_t* const slot_of_voxel = scratch.slot_of_voxel.data();
  std::int32_t voxels = 0;
  constexpr size_t kAhead = 12;
  for (size_t r = 0; r < runs; ++r) {
    if (r + kAhead < runs) __builtin_prefetch(&table[Mix(keys[r + kAhead]) & mask]);
    const std::uint64_t key = keys[r];
    size_t slot = Mix(key) & mask;
    while (table[slot].key != kEmpty && table[slot].key != key) slot = (slot + 1) & mask;
    if (table[slot].key == key) {
      run_voxel[r] = table[slot].voxel;
    } else {
      run_voxel[r] = voxels;
      table[slot] = VoxelScratch::Slot{key, voxels};
      slot_of_voxel[voxels++] = static_cast<std::uint32_t>(slot);
    }
  }
  for (std::int32_t v = 0; v < voxels; ++v) table[slot_of_voxel[v]].key = kEmpty;

  // 4. The sums, point by point in their order (so each centroid's floats add up as they always
  // did), without a branch.
  scratch.sums.assign(static_cast<size_t>(voxels), VoxelScratch::Sum{0.0f, 0.0f, 0.0f, 0});
  VoxelScratch::Sum* const sums = scratch.sums.data();
  int* const voxel_out = voxel_of_point != nullptr ? voxel_of_point->data() : nullptr;
  for (size_t i = 0; i < n; ++i) {
    const std::int32_t v = run_voxel[static_cast<size_t>(run_of[i])];
    VoxelScratch::Sum& s = sums[static_cast<size_t>(v)];
    s.x += points[i].x();
    s.y += points[i].y();
    s.z += points[i].z();
    ++s.count;
    if (voxel_out != nullptr) voxel_out[i] = v;
  }
  centroids->resize(static_cast<size_t>(voxels));
  Eigen::Vector3f* const out = centroids->data();
  for (std::int32_t v = 0; v < voxels; ++v) {
    const VoxelScratch::Sum& s = sums[v];
    out[v] = Eigen::Vector3f(s.x, s.y, s.z) / static_cast<float>(s.count);
  }
}

}  // namespace hpose
