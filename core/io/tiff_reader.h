#ifndef HPOSE_CORE_IO_TIFF_READER_H_
#define HPOSE_CORE_IO_TIFF_READER_H_

#include <string>

#include "core/common/status.h"
#include "core/io/decoded_image.h"
#include "core/io/image_header.h"

namespace hpose {

// Decodes the first image of a TIFF file (libtiff; any compression libtiff reads, strips or
// tiles) with its sample values unchanged: 1 to 4 interleaved channels of 8- or 16-bit unsigned
// integers (grey as PCL's grabbers and RGB-D datasets write depth, RGB, RGBA).
// Refuses before decoding anything but a regular file and images with a side above `max_side`
// (kOutOfRange, via CheckImageSize). Fails with kNotFound (missing), kDataLoss (not a TIFF,
// corrupt, truncated) or kInvalidArgument (a layout it does not decode: float or signed samples,
// other bit depths, palette, YCbCr or separate colour planes), each message naming the path.
Result<DecodedImage> ReadTiff(const std::string& path, int max_side = kMaxImageSide);

}  // namespace hpose

#endif  // HPOSE_CORE_IO_TIFF_READER_H_
