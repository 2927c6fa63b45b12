#ifndef HPOSE_CORE_DEPTH_INTRINSICS_H_
#define HPOSE_CORE_DEPTH_INTRINSICS_H_

#include "core/common/status.h"

namespace hpose {

// Pinhole intrinsics of a depth image, in pixels. The sensor (optical) frame is x right,
// y down, z forward along the optical axis, metres.
struct Intrinsics {
  int width = 0;
  int height = 0;
  double fx = 0.0;
  double fy = 0.0;
  double cx = 0.0;
  double cy = 0.0;

  // Kinect v1 depth camera scaled to width x height (640x480 native; SPEC §5:
  // fx 594.2, fy 591.0, cx 339.3, cy 242.7 at 640x480). 320x240 gives half of each.
  static Intrinsics KinectV1(int width = 640, int height = 480);

  // Checks sizes are positive and bounded (<= 8192), focal lengths finite and positive and the
  // principal point finite; then that the principal point lies within one image size of the
  // image ([-width, 2 width]) and that every pixel's ray is within 84 degrees of the optical
  // axis (|u - cx| <= 10 fx) with fx, fy <= 1e6 px, so back-projected points stay finite and
  // bounded. The message names the offending field.
  Status Validate() const;
};

}  // namespace hpose

#endif  // HPOSE_CORE_DEPTH_INTRINSICS_H_
