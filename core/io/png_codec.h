#ifndef HPOSE_CORE_IO_PNG_CODEC_H_
#define HPOSE_CORE_IO_PNG_CODEC_H_

#include <string>

#include "core/common/status.h"
#include "core/io/decoded_image.h"
#include "core/io/image_header.h"

namespace hpose {

// Decodes a PNG file (libpng) with its sample values unchanged: no gamma or colour conversion,
// transparency chunks ignored. Palette images come out as RGB, greys of 1, 2 or 4 bits as 8-bit
// grey; every other image keeps its channels and its 8 or 16 bits per sample.
// Refuses before decoding anything but a regular file and images with a side above `max_side`
// (kOutOfRange, via CheckImageSize). Fails with kNotFound (missing), kDataLoss (not a PNG, corrupt,
// truncated), each message naming the path.
Result<DecodedImage> ReadPng(const std::string& path, int max_side = kMaxImageSide);

// Encodes 8- or 16-bit pixels (interleaved samples, 1 to 4 channels, see DecodedImage; 16-bit
// samples in this machine's byte order) as a PNG file's bytes. `compression_level`: zlib's
// 0 (none) to 9 (smallest); at 0 and 1 every row gets the same (Sub) filter and zlib matches
// runs only, the fastest settings. Fails with kInvalidArgument for an inconsistent image.
Result<std::string> EncodePng(const DecodedImage& image, int compression_level = 1);

}  // namespace hpose

#endif  // HPOSE_CORE_IO_PNG_CODEC_H_
