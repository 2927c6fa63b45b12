#ifndef HPOSE_CORE_DEPTH_OCCLUDED_PIECE_MERGE_H_
#define HPOSE_CORE_DEPTH_OCCLUDED_PIECE_MERGE_H_

#include <vector>

#include <Eigen/Core>

#include "core/depth/cluster.h"

namespace hpose {

struct OccludedPieceOptions {
  // Largest depth step (metres, along the line of sight) from the hiding cluster to the piece
  // at their common edge: how far behind a body's near surface a limb of it can be seen. 0
  // disables the merge.
  double max_depth_gap_m = 0.30;
  // A piece has at most this fraction of the hiding cluster's points (a limb, not a second
  // object standing behind).
  double max_point_fraction = 0.5;
  // A piece whose lowest point lies less than this above the hiding cluster's lowest point
  // (ground frame), and whose top stays below the hiding cluster's mid-height, stands where that
  // cluster stands: a second object behind it, not a limb hanging from a joint the body hides
  // (a raised arm lies higher; a far foot joined with the arm above it reaches up past the
  // middle). Merged, it would add its voxels to the body's cluster and lower every template's
  // score there (a box 0.5 m behind a Nao, in its silhouette: 34 instead of 58, the robot
  // refused). 0: no such rule (before).
  double min_lift_m = 0.05;
  // Two points are neighbours in the image when the sensor sees them less than this angle
  // apart (radians), or less than two downsampling leaves apart at their distance, whichever
  // is larger (the veil filter removes a couple of pixels along every depth edge).
  double max_angle_rad = 0.008;
  double leaf_m = 0.008;
  // Pairs of clusters whose boxes lie too far apart for any point of one to neighbour a point of
  // the other are left out before the points are binned (the same merges; false: every cluster's
  // points binned and searched, the reference).
  bool screen_by_boxes = true;
};

// Merges into a cluster the smaller pieces of one object that it hides the joint of: an arm
// raised on the far side of a robot seen side-on shows above the shoulder, but where it meets
// the body it is behind the body, so the two share no point within the Euclidean tolerance.
// Piece B joins cluster A when B has at most max_point_fraction of A's points, does not stand
// where A stands (min_lift_m), and some point of B is A's neighbour in the image (seen from
// `sensor`, ground frame) while lying behind it by less than max_depth_gap_m: B continues behind
// A's silhouette. Objects apart in the image never merge, nor objects farther behind. Chains
// merge too (a hand behind an arm behind a body). Only `points` are used and kept; merged
// clusters keep the hiding cluster's place.
void MergeOccludedPieces(const Eigen::Vector3f& sensor, const OccludedPieceOptions& options,
                         std::vector<Cluster>* clusters);

}  // namespace hpose

#endif  // HPOSE_CORE_DEPTH_OCCLUDED_PIECE_MERGE_H_
