#ifndef HPOSE_CORE_DEPTH_CLUSTER_MERGE_H_
#define HPOSE_CORE_DEPTH_CLUSTER_MERGE_H_

#include <vector>

#include "core/depth/cluster.h"

namespace hpose {

// Merges clusters (ground frame, sensor above the origin) that are pieces of one object seen
// with a depth edge inside it: an arm hanging in front of a torso, once the veil filter has
// removed the mixed pixels between them. Two clusters are merged when, seen from the sensor,
// their bearing intervals overlap by at least `min_bearing_overlap` of the narrower one and
// their horizontal range intervals are less than `max_range_gap_m` apart; repeated until no
// pair qualifies. Objects side by side do not overlap in bearing; one standing behind another
// is farther than the gap. Only `points` are used and kept; bounds and centroid are left for
// the caller. min_bearing_overlap <= 0 disables.
void MergePiecesAlongSight(double min_bearing_overlap, double max_range_gap_m,
                           std::vector<Cluster>* clusters);

// A cluster as the sensor sees it: the least and greatest std::atan2(y, x) and std::hypot(x, y)
// of its points (in float, as the points are), computed for the extreme points only (to within
// a float rounding of the per-point functions). An empty cluster has lo above hi.
struct SightExtent {
  double bearing_lo = 1e300, bearing_hi = -1e300;
  double range_lo = 1e300, range_hi = -1e300;

  void Extend(const SightExtent& o);
};
SightExtent SightExtentOf(const Cluster& c);

}  // namespace hpose

#endif  // HPOSE_CORE_DEPTH_CLUSTER_MERGE_H_
