#include "core/io/depth_png.h"

#include <cstring>
#include <string>

#include "core/io/atomic_file.h"
#include "core/io/decoded_image.h"
#include "core/io/png_codec.h"

namespace hpose {

Result<DepthImage> ReadDepthPng(const std::string& path) {
  Result<DecodedImage> image = ReadPng(path);
  if (!image.ok()) return image.error();
  return DepthFromDecodedImage(*image, path);
}

Status WriteDepthPng(const DepthImage& depth, const std::string& path) {
  if (depth.width <= 0 || depth.height <= 0 ||
      depth.mm.size() != static_cast<size_t>(depth.width) * depth.height) {
    return MakeError(ErrorCode::kInvalidArgument,
                     path + ": cannot write a " + std::to_string(depth.width) + "x" +
                         std::to_string(depth.height) + " depth image holding " +
                         std::to_string(depth.mm.size()) + " values");
  }
  DecodedImage image;
  image.width = depth.width;
  image.height = depth.height;
  image.channels = 1;
  image.bits_per_sample = 16;
  image.bytes.resize(depth.mm.size() * sizeof(std::uint16_t));
  std::memcpy(image.bytes.data(), depth.mm.data(), image.bytes.size());
  Result<std::string> encoded = EncodePng(image);
  if (!encoded.ok()) return MakeError(encoded.error().code, path + ": " + encoded.error().message);
  return WriteFileAtomically(path, *encoded);
}

}  // namespace hpose
