#include "core/io/decoded_image.h"

#include <cstring>

namespace hpose {

Result<DepthImage> DepthFromDecodedImage(const DecodedImage& image, const std::string& path) {
  if (image.channels != 1 || image.bits_per_sample != 16) {
    return MakeError(ErrorCode::kInvalidArgument,
                     path + ": not a depth image: expected one 16-bit channel (millimetres), got " +
                         std::to_string(image.channels) + " channel(s) of " +
                         std::to_string(image.bits_per_sample) + "-bit samples" +
                         (image.channels >= 3 ? " (a colour image?)" : ""));
  }
  DepthImage depth(image.width, image.height);
  if (image.bytes.size() != depth.mm.size() * sizeof(std::uint16_t)) {
    return MakeError(ErrorCode::kInternal, path + ": decoded " +
                                               std::to_string(image.bytes.size()) +
                                               " bytes for a " + std::to_string(image.width) + "x" +
                                               std::to_string(image.height) + " image");
  }
  if (!depth.mm.empty()) std::memcpy(depth.mm.data(), image.bytes.data(), image.bytes.size());
  return depth;
}

}  // namespace hpose
