#ifndef HPOSE_CORE_IO_DECODED_IMAGE_H_
#define HPOSE_CORE_IO_DECODED_IMAGE_H_

#include <cstdint>
#include <string>
#include <vector>

#include "core/common/status.h"
#include "core/depth/depth_image.h"

namespace hpose {

// The pixels of an image file as its reader decoded them (PNG, TIFF): rows top to bottom, the
// samples of a pixel interleaved (grey; grey + alpha; red, green, blue; RGB + alpha), 16-bit
// samples in the byte order of this machine.
struct DecodedImage {
  int width = 0;                    // pixels.
  int height = 0;                   // pixels.
  int channels = 0;                 // samples per pixel, 1 to 4.
  int bits_per_sample = 0;          // 8 or 16.
  std::vector<std::uint8_t> bytes;  // height * width * channels * bits_per_sample / 8.

  size_t RowBytes() const { return static_cast<size_t>(width) * channels * (bits_per_sample / 8); }
};

// The depth image (millimetres) held by a single-channel 16-bit image. Fails with
// kInvalidArgument naming `path` and what it holds instead (e.g. three 8-bit channels: a colour
// image).
Result<DepthImage> DepthFromDecodedImage(const DecodedImage& image, const std::string& path);

}  // namespace hpose

#endif  // HPOSE_CORE_IO_DECODED_IMAGE_H_
