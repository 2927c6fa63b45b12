#ifndef HPOSE_SERVER_FRAME_H_
#define HPOSE_SERVER_FRAME_H_

#include <chrono>
#include <cstdint>
#include <string>

#include "core/depth/depth_image.h"
#include "core/depth/intrinsics.h"
#include "core/depth/point_cloud.h"

namespace hpose::server {

// One frame delivered by a FrameSource: either a depth image with its intrinsics or a point
// cloud in the sensor frame (x right, y down, z forward; metres).
struct Frame {
  std::uint64_t sequence = 0;  // 1, 2, 3, ... per source, counting reopenings and loops.
  // 0 at the first opening; +1 each time the source restarts its clock (a recording loops
  // back, a device reopens): source_time_s is comparable only within one epoch.
  std::uint64_t epoch = 0;
  double source_time_s = 0.0;  // the source's clock: device or recording timestamp, seconds.
  std::chrono::system_clock::time_point received;  // wall clock when read.
  std::chrono::steady_clock::time_point received_steady;
  std::string origin;  // file name, or the device URI.
  bool is_cloud = false;
  DepthImage depth;  // when !is_cloud, millimetres.
  Intrinsics intrinsics;
  PointCloud cloud;  // when is_cloud.
};

}  // namespace hpose::server

#endif  // HPOSE_SERVER_FRAME_H_
