#ifndef HPOSE_CORE_STEREO_RGB_IMAGE_IO_H_
#define HPOSE_CORE_STEREO_RGB_IMAGE_IO_H_

#include <string>

#include "core/common/status.h"
#include "core/stereo/rgb_image.h"

namespace hpose {

// Reads a colour image: PNG (libpng), JPEG (libjpeg) or TIFF (libtiff), told apart by their
// first bytes. Grey images are expanded to three equal channels; an alpha channel is dropped;
// 16-bit images are scaled to 8 bits. Fails with kNotFound (no such file), kDataLoss (another
// format, or not decodable: corrupt or truncated), kOutOfRange (a side above kMaxImageSide) or
// kInvalidArgument (a layout the readers do not decode, e.g. a CMYK JPEG), naming the path.
Result<RgbImage> ReadRgbImage(const std::string& path);

// Writes an 8-bit colour PNG atomically. Fails with kInvalidArgument for an invalid image and
// kInternal when the file cannot be written.
Status WriteRgbPng(const RgbImage& image, const std::string& path);

}  // namespace hpose

#endif  // HPOSE_CORE_STEREO_RGB_IMAGE_IO_H_
