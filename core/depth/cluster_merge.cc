#include "core/depth/cluster_merge.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hpose {
namespace {

// A key of a direction that increases with its bearing over (-pi, pi], as std::atan2 orders
// them (signed zeros included): 1 - x / (|x| + |y|) with the sign of y, in [-2, 2].
double BearingKey(double x, double y) {
  const double s = std::abs(x) + std::abs(y);
  if (s == 0.0) return std::copysign(std::signbit(x) ? 2.0 : 0.0, y);
  return std::copysign(1.0 - x / s, y);
}

}  // namespace

void SightExtent::Extend(const SightExtent& o) {
  bearing_lo = std::min(bearing_lo, o.bearing_lo);
  bearing_hi = std::max(bearing_hi, o.bearing_hi);
  range_lo = std::min(range_lo, o.range_lo);
  range_hi = std::max(range_hi, o.range_hi);
}

// The bearings and ranges of the extreme points only: one atan2 and one sqrt each instead of
// per point (a cluster has thousands of points).
SightExtent SightExtentOf(const Cluster& c) {
  SightExtent e;
  if (c.points.empty()) return e;
  double key_lo = std::numeric_limits<double>::max(),
         key_hi = std::numeric_limits<double>::lowest();
  double r2_lo = key_lo, r2_hi = key_hi;
  Eigen::Vector2d at_lo = Eigen::Vector2d::Zero(), at_hi = at_lo;
  for (const Eigen::Vector3f& p : c.points) {
    const double x = p.x(), y = p.y();
    const double key = BearingKey(x, y);
    if (key < key_lo) {
      key_lo = key;
      at_lo = {x, y};
    }
    if (key > key_hi) {
      key_hi = key;
      at_hi = {x, y};
    }
    const double r2 = x * x + y * y;  // exact: squares of floats fit a double.
    r2_lo = std::min(r2_lo, r2);
    r2_hi = std::max(r2_hi, r2);
  }
  // In float, as the points are: their atan2 and hypot.
  e.bearing_lo = std::atan2(static_cast<float>(at_lo.y()), static_cast<float>(at_lo.x()));
  e.bearing_hi = std::atan2(static_cast<float>(at_hi.y()), static_cast<float>(at_hi.x()));
  e.range_lo = static_cast<float>(std::sqrt(r2_lo));
  e.range_hi = static_cast<float>(std::sqrt(r2_hi));
  return e;
}

namespace {

bool SameObject(const SightExtent& a, const SightExtent& b, double min_overlap, double max_gap) {
  const double overlap =
      std::min(a.bearing_hi, b.bearing_hi) - std::max(a.bearing_lo, b.bearing_lo);
  const double narrower = std::min(a.bearing_hi - a.bearing_lo, b.bearing_hi - b.bearing_lo);
  if (overlap <= 0.0 || overlap < min_overlap * narrower) return false;
  const double gap = std::max(a.range_lo, b.range_lo) - std::min(a.range_hi, b.range_hi);
  return gap < max_gap;
}

}  // namespace

void MergePiecesAlongSight(double min_bearing_overlap, double max_range_gap_m,
                           std::vector<Cluster>* clusters) {
  if (min_bearing_overlap <= 0.0 || clusters->size() < 2) return;
  std::vector<SightExtent> extents;
  extents.reserve(clusters->size());
  for (const Cluster& c : *clusters) extents.push_back(SightExtentOf(c));
  bool merged = true;
  while (merged) {
    merged = false;
    for (size_t i = 0; i < clusters->size() && !merged; ++i) {
      for (size_t j = i + 1; j < clusters->size() && !merged; ++j) {
        if (!SameObject(extents[i], extents[j], min_bearing_overlap, max_range_gap_m)) continue;
        Cluster& into = (*clusters)[i];
        const Cluster& from = (*clusters)[j];
        into.points.insert(into.points.end(), from.points.begin(), from.points.end());
        extents[i].Extend(extents[j]);
        clusters->erase(clusters->begin() + static_cast<long>(j));
        extents.erase(extents.begin() + static_cast<long>(j));
        merged = true;
      }
    }
  }
}

}  // namespace hpose
