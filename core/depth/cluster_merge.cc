#include "core/depth/cluster_merge.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hpose {
namespace {

// A cluster as seen from the sensor: bearing and horizontal range intervals.
struct SightExtent {
  double bearing_lo = std::numeric_limits<double>::max();
  double bearing_hi = std::numeric_limits<double>::lowest();
  double range_lo = std::numeric_limits<double>::max();
  double range_hi = std::numeric_limits<double>::lowest();

  void Extend(const SightExtent& o) {
    bearing_lo = std::min(bearing_lo, o.bearing_lo);
    bearing_hi = std::max(bearing_hi, o.bearing_hi);
    range_lo = std::min(range_lo, o.range_lo);
    range_hi = std::max(range_hi, o.range_hi);
  }
};

SightExtent ExtentOf(const Cluster& c) {
  SightExtent e;
  for (const Eigen::Vector3f& p : c.points) {
    const double bearing = std::atan2(p.y(), p.x());
    const double range = std::hypot(p.x(), p.y());
    e.bearing_lo = std::min(e.bearing_lo, bearing);
    e.bearing_hi = std::max(e.bearing_hi, bearing);
    e.range_lo = std::min(e.range_lo, range);
    e.range_hi = std::max(e.range_hi, range);
  }
  return e;
}

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
  for (const Cluster& c : *clusters) extents.push_back(ExtentOf(c));
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
