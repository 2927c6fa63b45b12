#include "core/depth/depth_to_cloud.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "core/depth/point_lanes.h"

namespace hpose {
namespace {

// What the back-projection of one image needs, checked and in the inner loop's types.
struct Projection {
  const DepthImage* depth = nullptr;
  int stride = 1;
  int out_w = 0, out_h = 0;
  std::uint32_t min_mm = 1, max_mm = 65535;  // the range limits in raw millimetres.
  float inv_fx = 1.0f, inv_fy = 1.0f, cx = 0.0f, cy = 0.0f;
  bool keep_organised = false;
};

Result<Projection> Prepare(const DepthImage& depth, const Intrinsics& intrinsics,
                           const DepthToCloudOptions& options) {
  const Status valid = intrinsics.Validate();
  if (!valid.ok()) return valid.error();
  if (depth.width != intrinsics.width || depth.height != intrinsics.height) {
    return MakeError(ErrorCode::kInvalidArgument, "depth image is " + std::to_string(depth.width) +
                                                      "x" + std::to_string(depth.height) +
                                                      " but the intrinsics are for " +
                                                      std::to_string(intrinsics.width) + "x" +
                                                      std::to_string(intrinsics.height));
  }
  if (depth.mm.size() != static_cast<size_t>(depth.width) * depth.height) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "depth image holds " + std::to_string(depth.mm.size()) +
                         " values, expected width * height = " +
                         std::to_string(static_cast<size_t>(depth.width) * depth.height));
  }
  const Status usable = ValidateDepthToCloudOptions(options);
  if (!usable.ok()) return usable.error();
  Projection p;
  p.depth = &depth;
  p.stride = options.stride;
  p.out_w = (depth.width + p.stride - 1) / p.stride;
  p.out_h = (depth.height + p.stride - 1) / p.stride;
  // Range limits in raw millimetres so the inner loop compares integers.
  const double min_mm_d = std::ceil(options.min_range_m * 1000.0);
  const double max_mm_d = std::floor(options.max_range_m * 1000.0);
  p.min_mm = static_cast<std::uint32_t>(std::max(1.0, min_mm_d));
  p.max_mm = static_cast<std::uint32_t>(std::min(max_mm_d, 65535.0));
  p.inv_fx = static_cast<float>(1.0 / intrinsics.fx);
  p.inv_fy = static_cast<float>(1.0 / intrinsics.fy);
  p.cx = static_cast<float>(intrinsics.cx);
  p.cy = static_cast<float>(intrinsics.cy);
  p.keep_organised = options.keep_organised;
  return p;
}

// The cloud's storage: one allocation, the organised size being an upper bound of the
// unorganised one.
PointCloud Allocate(const Projection& p) {
  PointCloud cloud;
  cloud.points.resize(static_cast<size_t>(p.out_w) * p.out_h);
  if (p.keep_organised) {
    cloud.width = p.out_w;
    cloud.height = p.out_h;
  }
  return cloud;
}

// Pixels [u_begin, width) of row v from `out`'s slot n on; returns the next free slot. Every
// pixel is written at the next free slot, which advances only past valid ones unless the cloud
// keeps its organisation (then invalid pixels stay, as NaN): no branch per pixel.
size_t ProjectRowScalar(const Projection& p, int v, int u_begin, Eigen::Vector3f* out, size_t n) {
  const DepthImage& depth = *p.depth;
  const std::uint16_t* row = depth.mm.data() + static_cast<size_t>(v) * depth.width;
  const float ray_y = (static_cast<float>(v) - p.cy) * p.inv_fy;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const size_t keep_all = p.keep_organised ? 1 : 0;
  for (int u = u_begin; u < depth.width; u += p.stride) {
    const std::uint32_t mm = row[u];
    const bool valid = (mm >= p.min_mm) & (mm <= p.max_mm);
    const float z = valid ? static_cast<float>(mm) * 0.001f : nan;
    const float ray_x = (static_cast<float>(u) - p.cx) * p.inv_fx;
    out[n] = Eigen::Vector3f(ray_x * z, ray_y * z, z);
    n += valid ? 1 : keep_all;
  }
  return n;
}

#ifdef HPOSE_POINT_LANES
// Stride 1, sixteen pixels a step: the same operations as ProjectRowScalar lane by lane (the
// depth converted exactly, times 0.001f; the ray's slope (u - cx) * inv_fx; each coordinate one
// product), the valid lanes packed to the front (all of them when organised), then stored as
// points; every row, each finished by ProjectRowScalar. Returns the points written.
[[gnu::target("avx512f,avx512bw")]] size_t ProjectRowsAvx512(const Projection& p,
                                                             Eigen::Vector3f* out) {
  const DepthImage& depth = *p.depth;
  const int width = depth.width;
  const __m512 cx = _mm512_set1_ps(p.cx), inv_fx = _mm512_set1_ps(p.inv_fx);
  const __m512 milli = _mm512_set1_ps(0.001f);
  const __m512 nan = _mm512_set1_ps(std::numeric_limits<float>::quiet_NaN());
  const __m512i min_mm = _mm512_set1_epi32(static_cast<int>(p.min_mm));
  const __m512i max_mm = _mm512_set1_epi32(static_cast<int>(p.max_mm));
  // Masked conversions (all lanes): the unmasked ones start from an undefined register, which
  // GCC 12 reports as maybe uninitialised.
  const __mmask16 all = 0xFFFF;
  const __m512i iota = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  const PointInterleaver points;
  float* dst = out->data();
  size_t n = 0;
  for (int v = 0; v < depth.height; ++v) {
    const std::uint16_t* row = depth.mm.data() + static_cast<size_t>(v) * width;
    const __m512 ray_y = _mm512_set1_ps((static_cast<float>(v) - p.cy) * p.inv_fy);
    int u = 0;
    for (; u + 16 <= width; u += 16) {
      const __m512i mm = _mm512_maskz_cvtepu16_epi32(
          all, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(row + u)));
      const __mmask16 valid =
          _mm512_cmpge_epu32_mask(mm, min_mm) & _mm512_cmple_epu32_mask(mm, max_mm);
      __m512 z = _mm512_mul_ps(_mm512_maskz_cvtepi32_ps(all, mm), milli);
      const __m512 us = _mm512_maskz_cvtepi32_ps(all, _mm512_add_epi32(_mm512_set1_epi32(u), iota));
      __m512 ray_x = _mm512_mul_ps(_mm512_sub_ps(us, cx), inv_fx);
      int count = 16;
      if (p.keep_organised) {
        z = _mm512_mask_blend_ps(valid, nan, z);
      } else {
        count = __builtin_popcount(valid);
        z = _mm512_maskz_compress_ps(valid, z);
        ray_x = _mm512_maskz_compress_ps(valid, ray_x);
      }
      const __m512 x = _mm512_mul_ps(ray_x, z);
      const __m512 y = _mm512_mul_ps(ray_y, z);
      points.Store(x, y, z, count, dst + 3 * n);
      n += static_cast<size_t>(count);
    }
    n = ProjectRowScalar(p, v, u, out, n);
  }
  return n;
}

// Stride 1, eight pixels a step with AVX2: the same operations as ProjectRowScalar lane by lane
// (the readings' range tested as signed integers: they and the limits are below 2^16). The
// valid lanes are packed to the front by one permutation, and all eight stored: n never passes
// the pixels done, so the stores stay inside the cloud, and what lies past the valid points is
// overwritten or cut.
[[gnu::target("avx2")]] size_t ProjectRowsAvx2(const Projection& p, Eigen::Vector3f* out) {
  const DepthImage& depth = *p.depth;
  const int width = depth.width;
  const __m256 cx = _mm256_set1_ps(p.cx), inv_fx = _mm256_set1_ps(p.inv_fx);
  const __m256 milli = _mm256_set1_ps(0.001f);
  const __m256 nan = _mm256_set1_ps(std::numeric_limits<float>::quiet_NaN());
  const __m256i min_mm = _mm256_set1_epi32(static_cast<int>(p.min_mm));
  const __m256i max_mm = _mm256_set1_epi32(static_cast<int>(p.max_mm));
  const __m256i iota = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const PointShuffles8 shuffles;
  float* dst = out->data();
  size_t n = 0;
  for (int v = 0; v < depth.height; ++v) {
    const std::uint16_t* row = depth.mm.data() + static_cast<size_t>(v) * width;
    const __m256 ray_y = _mm256_set1_ps((static_cast<float>(v) - p.cy) * p.inv_fy);
    int u = 0;
    for (; u + 8 <= width; u += 8) {
      const __m256i mm =
          _mm256_cvtepu16_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(row + u)));
      const __m256 invalid = _mm256_castsi256_ps(
          _mm256_or_si256(_mm256_cmpgt_epi32(min_mm, mm), _mm256_cmpgt_epi32(mm, max_mm)));
      __m256 z = _mm256_mul_ps(_mm256_cvtepi32_ps(mm), milli);
      const __m256 us = _mm256_cvtepi32_ps(_mm256_add_epi32(_mm256_set1_epi32(u), iota));
      __m256 ray_x = _mm256_mul_ps(_mm256_sub_ps(us, cx), inv_fx);
      int count = 8;
      if (p.keep_organised) {
        z = _mm256_blendv_ps(z, nan, invalid);
      } else {
        const int valid = ~_mm256_movemask_ps(invalid) & 0xFF;
        count = __builtin_popcount(static_cast<unsigned>(valid));
        const __m256i packed = PackLanes8(valid);
        z = _mm256_permutevar8x32_ps(z, packed);
        ray_x = _mm256_permutevar8x32_ps(ray_x, packed);
      }
      shuffles.Store(_mm256_mul_ps(ray_x, z), _mm256_mul_ps(ray_y, z), z, dst + 3 * n);
      n += static_cast<size_t>(count);
    }
    n = ProjectRowScalar(p, v, u, out, n);
  }
  return n;
}

#else
size_t ProjectRowsAvx512(const Projection&, Eigen::Vector3f*) { return 0; }
size_t ProjectRowsAvx2(const Projection&, Eigen::Vector3f*) { return 0; }
#endif

Result<PointCloud> Project(const DepthImage& depth, const Intrinsics& intrinsics,
                           const DepthToCloudOptions& options, LanePath path) {
  Result<Projection> prepared = Prepare(depth, intrinsics, options);
  if (!prepared.ok()) return prepared.error();
  const Projection& p = *prepared;
  PointCloud cloud = Allocate(p);
  Eigen::Vector3f* out = cloud.points.data();
  size_t n = 0;
  if (cloud.points.empty()) return cloud;  // (no storage to point into)
  if (path == LanePath::kFastest && p.stride == 1 && PointLanesAvailable()) {
    n = ProjectRowsAvx512(p, out);
  } else if (path != LanePath::kScalar && p.stride == 1 && PointLanes8Available()) {
    n = ProjectRowsAvx2(p, out);
  } else {
    for (int v = 0; v < depth.height; v += p.stride) n = ProjectRowScalar(p, v, 0, out, n);
  }
  cloud.points.resize(n);
  return cloud;
}

}  // namespace

Status ValidateDepthToCloudOptions(const DepthToCloudOptions& options) {
  if (options.stride < 1) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "depth to cloud: stride " + std::to_string(options.stride) + " must be >= 1");
  }
  if (!(options.min_range_m >= 0.0) || !(options.max_range_m > options.min_range_m)) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "depth to cloud: need 0 <= min_range_m < max_range_m, got " +
                         std::to_string(options.min_range_m) + " and " +
                         std::to_string(options.max_range_m));
  }
  return Status::Ok();
}

Result<PointCloud> DepthToCloud(const DepthImage& depth, const Intrinsics& intrinsics,
                                const DepthToCloudOptions& options) {
  return Project(depth, intrinsics, options, LanePath::kFastest);
}

Result<PointCloud> DepthToCloudAvx2(const DepthImage& depth, const Intrinsics& intrinsics,
                                    const DepthToCloudOptions& options) {
  assert(DepthToCloudAvx2Available());
  return Project(depth, intrinsics, options, LanePath::kAvx2);
}

Result<PointCloud> DepthToCloudScalar(const DepthImage& depth, const Intrinsics& intrinsics,
                                      const DepthToCloudOptions& options) {
  return Project(depth, intrinsics, options, LanePath::kScalar);
}

std::string NoPointInRangeReason(const DepthImage& depth, const DepthToCloudOptions& options) {
  const std::string image =
      std::to_string(depth.width) + "x" + std::to_string(depth.height) + " depth image";
  std::size_t readings = 0;
  std::uint16_t lo = 65535, hi = 0;
  for (const std::uint16_t v : depth.mm) {
    if (v == 0) continue;
    ++readings;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  if (readings == 0) return "no pixel of the " + image + " holds a reading (every value is 0)";
  const auto metres = [](double m) {
    char text[32];
    std::snprintf(text, sizeof text, "%.2f", m);
    return std::string(text);
  };
  std::string out = "none of the " + std::to_string(readings) + " readings of the " + image +
                    " lies within " + metres(options.min_range_m) + "-" +
                    metres(options.max_range_m) + " m (they span " + std::to_string(lo) + "-" +
                    std::to_string(hi) + " mm";
  if (hi < 100) out += "; depth images hold millimetres, and one in metres reads so";
  return out + ")";
}

bool DepthToCloudVectorised() { return PointLanesAvailable() || PointLanes8Available(); }

bool DepthToCloudAvx2Available() { return PointLanes8Available(); }

}  // namespace hpose
