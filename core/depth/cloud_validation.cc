#include "core/depth/cloud_validation.h"

#include <cassert>
#include <cmath>
#include <sstream>
#include <string>

#include "core/depth/point_lanes.h"

namespace hpose {
namespace {

bool IsMissing(const Eigen::Vector3f& p) { return p.array().isNaN().any(); }

bool IsWithin(const Eigen::Vector3f& p, float limit) {
  // NaN-safe: the comparison fails for NaN, and infinities exceed any finite limit.
  return std::abs(p.x()) <= limit && std::abs(p.y()) <= limit && std::abs(p.z()) <= limit;
}

std::string Describe(const Eigen::Vector3f& p) {
  std::ostringstream out;
  out << "(" << p.x() << ", " << p.y() << ", " << p.z() << ")";
  return out.str();
}

// The scalar end of the vector counts: points [from, size) added to `count` into `within`, or
// false at a point neither within nor missing.
bool CountWithinFrom(const PointCloud& cloud, float limit, size_t from, size_t count,
                     size_t* within) {
  for (size_t i = from; i < cloud.size(); ++i) {
    const Eigen::Vector3f& p = cloud.points[i];
    if (IsWithin(p, limit)) {
      ++count;
    } else if (!IsMissing(p)) {
      return false;
    }
  }
  *within = count;
  return true;
}

// Counts the points within +-limit on every axis (no NaN among their coordinates) into
// `within`, sixteen a step; false as soon as a point is neither within nor missing (NaN): then
// the caller looks again the scalar way, to name it.
#ifdef HPOSE_POINT_LANES
[[gnu::target("avx512f")]] bool CountWithinAvx512(const PointCloud& cloud, float limit,
                                                  size_t* within) {
  const PointDeinterleaver lanes;
  const __m512 lim = _mm512_set1_ps(limit);
  const size_t n = cloud.size();
  size_t count = 0, i = 0;
  for (; i + 16 <= n; i += 16) {
    const PointLanes p = lanes.Load(cloud.points[i].data());
    // |v| <= limit fails for NaN; v != v only for NaN.
    const __mmask16 in = _mm512_cmp_ps_mask(_mm512_abs_ps(p.x), lim, _CMP_LE_OQ) &
                         _mm512_cmp_ps_mask(_mm512_abs_ps(p.y), lim, _CMP_LE_OQ) &
                         _mm512_cmp_ps_mask(_mm512_abs_ps(p.z), lim, _CMP_LE_OQ);
    const __mmask16 missing = _mm512_cmp_ps_mask(p.x, p.x, _CMP_UNORD_Q) |
                              _mm512_cmp_ps_mask(p.y, p.y, _CMP_UNORD_Q) |
                              _mm512_cmp_ps_mask(p.z, p.z, _CMP_UNORD_Q);
    if (static_cast<__mmask16>(in | missing) != 0xFFFF) return false;
    count += static_cast<size_t>(__builtin_popcount(in));
  }
  return CountWithinFrom(cloud, limit, i, count, within);
}

// The same eight points a step with AVX2.
[[gnu::target("avx2")]] bool CountWithinAvx2(const PointCloud& cloud, float limit, size_t* within) {
  const PointShuffles8 shuffles;
  const __m256 lim = _mm256_set1_ps(limit);
  const __m256 magnitude = _mm256_castsi256_ps(_mm256_set1_epi32(0x7FFFFFFF));
  const size_t n = cloud.size();
  size_t count = 0, i = 0;
  for (; i + 8 <= n; i += 8) {
    const PointLanes8 p = shuffles.Load(cloud.points[i].data());
    const __m256 in =
        _mm256_and_ps(_mm256_and_ps(_mm256_cmp_ps(_mm256_and_ps(p.x, magnitude), lim, _CMP_LE_OQ),
                                    _mm256_cmp_ps(_mm256_and_ps(p.y, magnitude), lim, _CMP_LE_OQ)),
                      _mm256_cmp_ps(_mm256_and_ps(p.z, magnitude), lim, _CMP_LE_OQ));
    const __m256 missing = _mm256_or_ps(
        _mm256_or_ps(_mm256_cmp_ps(p.x, p.x, _CMP_UNORD_Q), _mm256_cmp_ps(p.y, p.y, _CMP_UNORD_Q)),
        _mm256_cmp_ps(p.z, p.z, _CMP_UNORD_Q));
    const int in_bits = _mm256_movemask_ps(in);
    if ((in_bits | _mm256_movemask_ps(missing)) != 0xFF) return false;
    count += static_cast<size_t>(__builtin_popcount(static_cast<unsigned>(in_bits)));
  }
  return CountWithinFrom(cloud, limit, i, count, within);
}

#else
bool CountWithinAvx512(const PointCloud&, float, size_t*) { return false; }
bool CountWithinAvx2(const PointCloud&, float, size_t*) { return false; }
#endif

Status Validate(const PointCloud& cloud, const CloudLimits& limits, std::size_t* finite_points,
                LanePath path) {
  if (cloud.size() > limits.max_points) {
    return MakeError(ErrorCode::kInvalidArgument, "the cloud has " + std::to_string(cloud.size()) +
                                                      " points, more than " +
                                                      std::to_string(limits.max_points));
  }
  const float limit = static_cast<float>(limits.max_abs_coordinate_m);
  size_t valid_within = 0;
  // The vector counts stop at the first point that fails; the scalar pass below then names it.
  const bool counted = (path == LanePath::kFastest && PointLanesAvailable())
                           ? CountWithinAvx512(cloud, limit, &valid_within)
                           : (path != LanePath::kScalar && PointLanes8Available() &&
                              CountWithinAvx2(cloud, limit, &valid_within));
  if (counted) {
    if (finite_points != nullptr) *finite_points = valid_within;
    return Status::Ok();
  }
  size_t bad = 0;
  size_t first_bad = 0;
  size_t within = 0;
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f& p = cloud.points[i];
    if (IsWithin(p, limit)) {
      ++within;
      continue;
    }
    if (IsMissing(p)) continue;
    if (bad == 0) first_bad = i;
    ++bad;
  }
  if (finite_points != nullptr) *finite_points = within;
  if (bad == 0) return Status::Ok();
  std::ostringstream limit_text;
  limit_text << limits.max_abs_coordinate_m;
  return MakeError(ErrorCode::kInvalidArgument,
                   "point " + std::to_string(first_bad) + " " + Describe(cloud.points[first_bad]) +
                       " is infinite or farther than " + limit_text.str() +
                       " m from the sensor on some axis (" + std::to_string(bad) + " of " +
                       std::to_string(cloud.size()) + " points are; missing readings must be NaN)");
}

}  // namespace

Status ValidateCloud(const PointCloud& cloud, const CloudLimits& limits,
                     std::size_t* finite_points) {
  return Validate(cloud, limits, finite_points, LanePath::kFastest);
}

Status ValidateCloudScalar(const PointCloud& cloud, const CloudLimits& limits,
                           std::size_t* finite_points) {
  return Validate(cloud, limits, finite_points, LanePath::kScalar);
}

Status ValidateCloudAvx2(const PointCloud& cloud, const CloudLimits& limits,
                         std::size_t* finite_points) {
  assert(CloudValidationAvx2Available());
  return Validate(cloud, limits, finite_points, LanePath::kAvx2);
}

bool CloudValidationAvx2Available() { return PointLanes8Available(); }

Status ValidateFloor(const FloorEstimate& floor, const CloudLimits& limits) {
  const Eigen::Matrix4d& m = floor.ground_from_sensor.matrix();
  if (!floor.plane_sensor.allFinite() || !m.allFinite()) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "floor: the plane or the ground frame is not finite (a degenerate floor, "
                     "e.g. the optical axis perpendicular to it)");
  }
  const Eigen::Matrix3d r = floor.ground_from_sensor.linear();
  if (!(((r * r.transpose()) - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-6) ||
      !(r.determinant() > 0.0)) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "floor: the ground frame's rotation is not a rotation (degenerate floor)");
  }
  if (!(floor.height_m >= 0.0 && floor.height_m <= limits.max_abs_coordinate_m)) {
    std::ostringstream out;
    out << "floor: the sensor height " << floor.height_m << " m is outside [0, "
        << limits.max_abs_coordinate_m << "]";
    return MakeError(ErrorCode::kInvalidArgument, out.str());
  }
  return Status::Ok();
}

}  // namespace hpose
