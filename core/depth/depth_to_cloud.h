#ifndef HPOSE_CORE_DEPTH_DEPTH_TO_CLOUD_H_
#define HPOSE_CORE_DEPTH_DEPTH_TO_CLOUD_H_

#include <string>

#include "core/common/status.h"
#include "core/depth/depth_image.h"
#include "core/depth/intrinsics.h"
#include "core/depth/point_cloud.h"

namespace hpose {

struct DepthToCloudOptions {
  double min_range_m = 0.4;  // readings nearer than this are dropped (Kinect v1: 0.8 m nominal).
  double max_range_m = 4.5;  // readings farther than this are dropped.
  int stride = 1;  // take every stride-th pixel in u and v (2 turns 640x480 into 320x240).
  bool keep_organised = false;  // true: keep invalid pixels as NaN and set width/height.
};

// kInvalidArgument naming what is wrong unless stride >= 1 and 0 <= min_range_m < max_range_m.
Status ValidateDepthToCloudOptions(const DepthToCloudOptions& options);

// Back-projects a depth image through pinhole intrinsics into the sensor frame.
// Fails (kInvalidArgument) when the intrinsics are invalid or do not match the image size.
// Sixteen pixels a step with AVX-512 where the CPU has it, eight with AVX2 where it has that
// (DepthToCloudVectorised(); stride 1), the scalar loop otherwise: DepthToCloudScalar, the
// reference. All compute every coordinate with the same float operations in the same order, so
// their clouds are equal to the bit. DepthToCloudAvx2 takes the AVX2 path whatever else the CPU
// has (only where DepthToCloudAvx2Available()), for tests and benchmarks.
Result<PointCloud> DepthToCloud(const DepthImage& depth, const Intrinsics& intrinsics,
                                const DepthToCloudOptions& options = {});
Result<PointCloud> DepthToCloudScalar(const DepthImage& depth, const Intrinsics& intrinsics,
                                      const DepthToCloudOptions& options = {});
bool DepthToCloudVectorised();
Result<PointCloud> DepthToCloudAvx2(const DepthImage& depth, const Intrinsics& intrinsics,
                                    const DepthToCloudOptions& options = {});
bool DepthToCloudAvx2Available();

// Why the image gives no point within the options' range, as the end of an error message:
// "no pixel of the 640x480 depth image holds a reading (every value is 0)", or where its
// readings lie against the range (with a word on units when they are all a few millimetres,
// as an image in metres reads).
std::string NoPointInRangeReason(const DepthImage& depth, const DepthToCloudOptions& options);

}  // namespace hpose

#endif  // HPOSE_CORE_DEPTH_DEPTH_TO_CLOUD_H_
