#include "core/depth/range_image.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hpose {

RangeImage RangeImage::FromCloud(const PointCloud& cloud, double focal_px) {
  RangeImage r;
  r.focal_ = focal_px;
  constexpr double kMaxTan = 3.0;
  // Slopes in float like the points (x / z, y / z); branch-free over the NaN holes of an
  // organised cloud: a point not in front of the sensor leaves the extent unchanged.
  constexpr float kInf = std::numeric_limits<float>::infinity();
  float tx_lo_f = kInf, tx_hi_f = -kInf, ty_lo_f = kInf, ty_hi_f = -kInf;
  for (const Eigen::Vector3f& p : cloud.points) {
    const bool valid = p.allFinite() && p.z() > 0.0f;
    const float tx = p.x() / p.z(), ty = p.y() / p.z();
    tx_lo_f = std::min(tx_lo_f, valid ? tx : kInf);
    tx_hi_f = std::max(tx_hi_f, valid ? tx : -kInf);
    ty_lo_f = std::min(ty_lo_f, valid ? ty : kInf);
    ty_hi_f = std::max(ty_hi_f, valid ? ty : -kInf);
  }
  if (!(tx_lo_f <= tx_hi_f)) return r;  // no point in front of the sensor.
  const double tx_lo = std::clamp<double>(tx_lo_f, -kMaxTan, kMaxTan);
  const double tx_hi = std::clamp<double>(tx_hi_f, -kMaxTan, kMaxTan);
  const double ty_lo = std::clamp<double>(ty_lo_f, -kMaxTan, kMaxTan);
  const double ty_hi = std::clamp<double>(ty_hi_f, -kMaxTan, kMaxTan);
  r.u0_ = -tx_lo * focal_px;
  r.v0_ = -ty_lo * focal_px;
  r.width_ = static_cast<int>((tx_hi - tx_lo) * focal_px) + 1;
  r.height_ = static_cast<int>((ty_hi - ty_lo) * focal_px) + 1;
  // Nearest depth per bin, +inf while empty (0 = unknown once done).
  r.depth_.assign(static_cast<size_t>(r.width_) * r.height_, kInf);
  for (const Eigen::Vector3f& p : cloud.points) {
    if (!p.allFinite() || p.z() <= 0.0f) continue;
    // In double and range-checked before the conversion: a point almost in the optical
    // centre's plane has an enormous ray slope that no int holds. Within [0, size) truncation
    // is the floor, and floor(x) lies in [0, size) exactly when x does (size is an integer).
    const double uf = static_cast<double>(p.x() / p.z()) * focal_px + r.u0_;
    const double vf = static_cast<double>(p.y() / p.z()) * focal_px + r.v0_;
    if (!(uf >= 0.0 && vf >= 0.0 && uf < r.width_ && vf < r.height_)) continue;
    float& d = r.depth_[static_cast<size_t>(vf) * r.width_ + static_cast<size_t>(uf)];
    d = std::min(d, p.z());
  }
  for (float& d : r.depth_) d = d == kInf ? 0.0f : d;
  return r;
}

bool RangeImage::Covers(const Eigen::Vector3d& p) const {
  return p.z() > 1e-3 && CoversRay(p.x() / p.z(), p.y() / p.z());
}

float RangeImage::NearestAround(const Eigen::Vector3d& p, int radius) const {
  if (!Covers(p)) return 0.0f;
  return NearestAroundRay(p.x() / p.z(), p.y() / p.z(), radius);
}

}  // namespace hpose
