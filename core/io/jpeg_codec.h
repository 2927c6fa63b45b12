#ifndef HPOSE_CORE_IO_JPEG_CODEC_H_
#define HPOSE_CORE_IO_JPEG_CODEC_H_

#include <string>

#include "core/common/status.h"
#include "core/io/decoded_image.h"
#include "core/io/image_header.h"

namespace hpose {

// Decodes a JPEG file (libjpeg) to 8-bit samples: a grey image as one channel, a colour image
// (YCbCr or RGB) as three, red, green, blue. The decoder's settings are libjpeg's defaults (the
// accurate integer DCT, smooth chroma upsampling), as OpenCV's reader uses them.
// Refuses before decoding anything but a regular file and images with a side above `max_side`
// (kOutOfRange, via CheckImageSize). Fails with kNotFound (missing), kDataLoss (not a JPEG; data
// libjpeg finds damaged: truncated, bad codes, a marker inside it) or kInvalidArgument (CMYK and
// YCCK images), naming the path. Stray bytes between markers are read past, as OpenCV does.
Result<DecodedImage> ReadJpeg(const std::string& path, int max_side = kMaxImageSide);

// The same for a JPEG file's bytes in memory; `name` stands for the path in messages.
Result<DecodedImage> DecodeJpeg(const std::string& bytes, const std::string& name,
                                int max_side = kMaxImageSide);

// Encodes 8-bit grey or RGB pixels (1 or 3 channels) as a baseline JPEG file's bytes at
// `quality` (1 to 100, libjpeg's scale; chroma subsampled 2x2 as libjpeg does by default). Fails
// with kInvalidArgument for an inconsistent image or a quality out of range.
Result<std::string> EncodeJpeg(const DecodedImage& image, int quality);

}  // namespace hpose

#endif  // HPOSE_CORE_IO_JPEG_CODEC_H_
