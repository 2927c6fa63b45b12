#include "core/depth/cloud_validation.h"

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
  for (; i < n; ++i) {
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

#else
bool CountWithinAvx512(const PointCloud&, float, size_t*) { return false; }
#endif

}  // namespace

Status ValidateCloud(const PointCloud& cloud, const CloudLimits& limits,
                     std::size_t* finite_points) {
  if (cloud.size() > limits.max_points) {
    return MakeError(ErrorCode::kInvalidArgument, "the cloud has " + std::to_string(cloud.size()) +
                                                      " points, more than " +
                                                      std::to_string(limits.max_points));
  }
  const float limit = static_cast<float>(limits.max_abs_coordinate_m);
  size_t valid_within = 0;
  if (PointLanesAvailable() && CountWithinAvx512(cloud, limit, &valid_within)) {
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
