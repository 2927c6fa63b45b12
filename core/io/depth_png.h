#ifndef HPOSE_CORE_IO_DEPTH_PNG_H_
#define HPOSE_CORE_IO_DEPTH_PNG_H_

#include <string>

#include "core/common/status.h"
#include "core/depth/depth_image.h"

namespace hpose {

// Reads a single-channel 16-bit PNG of depth in millimetres (TUM RGB-D style, 0 = no reading).
// Fails with kNotFound (missing), kDataLoss (not a PNG, corrupt, truncated) or kInvalidArgument
// (not 16-bit single channel), naming the path and what is wrong.
Result<DepthImage> ReadDepthPng(const std::string& path);

// Writes a 16-bit single-channel PNG atomically.
Status WriteDepthPng(const DepthImage& depth, const std::string& path);

}  // namespace hpose

#endif  // HPOSE_CORE_IO_DEPTH_PNG_H_
