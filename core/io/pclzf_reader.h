#ifndef HPOSE_CORE_IO_PCLZF_READER_H_
#define HPOSE_CORE_IO_PCLZF_READER_H_

#include <cstdint>
#include <string>
#include <vector>

#include "core/common/status.h"

namespace hpose {

// PCL's LZF image format (.pclzf, as its grabbers record Kinect frames), read without PCL.

// The raw 16-bit values of a "depth16" image, row-major.
struct PclzfDepth16 {
  int width = 0;                      // pixels.
  int height = 0;                     // pixels.
  std::vector<std::uint16_t> values;  // in units of the .xml's z_multiplication_factor.
};

// Reads a .pclzf holding a depth16 image (a "PCLZF" signature, width, height, 16-byte image type,
// packed and unpacked sizes, LZF data). Sides above kMaxImageSide are refused before unpacking
// (kOutOfRange). Fails with kNotFound (missing), kInvalidArgument (another image type, e.g. an
// _rgb.pclzf) or kDataLoss (corrupt or truncated, naming what), each message naming the path.
Result<PclzfDepth16> ReadPclzfDepth16(const std::string& path);

// The <depth> camera of the .xml PCL's grabber writes beside its .pclzf images.
struct PclzfDepthCamera {
  double focal_length_x = 0.0;  // pixels.
  double focal_length_y = 0.0;
  double principal_point_x = 0.0;
  double principal_point_y = 0.0;
  double z_multiplication_factor = 0.0;  // metres per raw depth unit.
};

// Reads the <depth> element's values; kDataLoss naming the file and the value missing or not a
// number.
Result<PclzfDepthCamera> ReadPclzfDepthCamera(const std::string& xml_path);

}  // namespace hpose

#endif  // HPOSE_CORE_IO_PCLZF_READER_H_
