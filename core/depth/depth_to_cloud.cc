#include "core/depth/depth_to_cloud.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

namespace hpose {

Result<PointCloud> DepthToCloud(const DepthImage& depth, const Intrinsics& intrinsics,
                                const DepthToCloudOptions& options) {
  const Status valid = intrinsics.Validate();
  if (!valid.ok()) return valid.error();
  if (depth.width != intrinsics.width || depth.height != intrinsics.height) {
    return MakeError(ErrorCode::kInvalidArgument, "depth image is " + std::to_string(depth.width) +
                                                      "x" + std::to_string(depth.height) +
                                                      " but the intrinsics are for " +
                                                      std::to_string(intrinsics.width) + "x" +
                                                      std::to_string(intrinsics.height));
  }
  if (depth.mm.size() != static_cast<size_t>(depth.width) * depth.height) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "depth image holds " + std::to_string(depth.mm.size()) +
                         " values, expected width * height = " +
                         std::to_string(static_cast<size_t>(depth.width) * depth.height));
  }
  if (options.stride < 1) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "depth to cloud: stride " + std::to_string(options.stride) + " must be >= 1");
  }
  if (!(options.min_range_m >= 0.0) || !(options.max_range_m > options.min_range_m)) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "depth to cloud: need 0 <= min_range_m < max_range_m, got " +
                         std::to_string(options.min_range_m) + " and " +
                         std::to_string(options.max_range_m));
  }

  const int stride = options.stride;
  const int out_w = (depth.width + stride - 1) / stride;
  const int out_h = (depth.height + stride - 1) / stride;
  // Range limits in raw millimetres so the inner loop compares integers.
  const double min_mm_d = std::ceil(options.min_range_m * 1000.0);
  const double max_mm_d = std::floor(options.max_range_m * 1000.0);
  const std::uint32_t min_mm = static_cast<std::uint32_t>(std::max(1.0, min_mm_d));
  const std::uint32_t max_mm = static_cast<std::uint32_t>(std::min(max_mm_d, 65535.0));

  const float inv_fx = static_cast<float>(1.0 / intrinsics.fx);
  const float inv_fy = static_cast<float>(1.0 / intrinsics.fy);
  const float cx = static_cast<float>(intrinsics.cx);
  const float cy = static_cast<float>(intrinsics.cy);
  const float nan = std::numeric_limits<float>::quiet_NaN();

  PointCloud cloud;
  // One allocation: the organised size is an upper bound of the unorganised one.
  cloud.points.resize(static_cast<size_t>(out_w) * out_h);
  if (options.keep_organised) {
    cloud.width = out_w;
    cloud.height = out_h;
  }
  // Every pixel is written at the next free slot, which advances only past valid ones unless
  // the cloud keeps its organisation (then invalid pixels stay, as NaN): no branch per pixel.
  Eigen::Vector3f* out = cloud.points.data();
  size_t n = 0;
  const size_t keep_all = options.keep_organised ? 1 : 0;
  for (int v = 0; v < depth.height; v += stride) {
    const std::uint16_t* row = depth.mm.data() + static_cast<size_t>(v) * depth.width;
    const float ray_y = (static_cast<float>(v) - cy) * inv_fy;
    for (int u = 0; u < depth.width; u += stride) {
      const std::uint32_t mm = row[u];
      const bool valid = (mm >= min_mm) & (mm <= max_mm);
      const float z = valid ? static_cast<float>(mm) * 0.001f : nan;
      const float ray_x = (static_cast<float>(u) - cx) * inv_fx;
      out[n] = Eigen::Vector3f(ray_x * z, ray_y * z, z);
      n += valid ? 1 : keep_all;
    }
  }
  cloud.points.resize(n);
  return cloud;
}

}  // namespace hpose
