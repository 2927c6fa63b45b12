#ifndef HPOSE_CORE_IO_IMAGE_HEADER_H_
#define HPOSE_CORE_IO_IMAGE_HEADER_H_

#include <string>

#include "core/common/status.h"

namespace hpose {

// The largest image side hpose decodes (pixels); as Intrinsics allow.
constexpr int kMaxImageSide = 8192;

enum class ImageFormat { kOther, kPng, kJpeg, kTiff };

struct ImageSize {
  bool known = false;  // false: a format whose header is not parsed here (BMP, PPM, ...).
  int width = 0;       // pixels.
  int height = 0;
  ImageFormat format = ImageFormat::kOther;  // what the first bytes announce, when known.
};

// Reads an image's size and format from its header, without decoding it: PNG (IHDR), JPEG (SOF)
// and TIFF (the first IFD's ImageWidth / ImageLength), told apart by their first bytes. Other
// formats give known = false. Fails with kDataLoss when a recognised header is truncated or
// inconsistent, like CheckInputFile (regular files only) otherwise.
Result<ImageSize> ReadImageSize(const std::string& path);

// Refuses, before any decoding, a file that is not a regular file or an image with a side
// above `max_side` (kOutOfRange: "30000x30000 px, at most 8192 px per side"); formats whose
// header is not parsed pass.
Status CheckImageSize(const std::string& path, int max_side = kMaxImageSide);

}  // namespace hpose

#endif  // HPOSE_CORE_IO_IMAGE_HEADER_H_
