#include "core/stereo/rgb_image_io.h"

#include <cstring>

#include "core/io/atomic_file.h"
#include "core/io/decoded_image.h"
#include "core/io/image_header.h"
#include "core/io/jpeg_codec.h"
#include "core/io/png_codec.h"
#include "core/io/tiff_reader.h"

namespace hpose {
namespace {

// 8-bit red, green, blue from a decoded image: grey repeated in all three, alpha dropped, 16-bit
// samples scaled by 1/257 to the nearest integer.
Result<RgbImage> ToRgb(const DecodedImage& image, const std::string& path) {
  if (image.bits_per_sample != 8 && image.bits_per_sample != 16) {
    return MakeError(ErrorCode::kDataLoss, path + ": unsupported pixel depth (need 8 or 16 bit)");
  }
  if (image.channels < 1 || image.channels > 4 ||
      image.bytes.size() != image.RowBytes() * static_cast<size_t>(image.height)) {
    return MakeError(ErrorCode::kDataLoss,
                     path + ": unsupported channel count " + std::to_string(image.channels));
  }
  RgbImage out(image.width, image.height);
  const size_t pixels = static_cast<size_t>(image.width) * image.height;
  const int c = image.channels;
  const bool wide = image.bits_per_sample == 16;
  for (size_t i = 0; i < pixels; ++i) {
    for (int k = 0; k < 3; ++k) {
      const size_t sample = i * c + (c >= 3 ? k : 0);
      std::uint8_t value;
      if (wide) {
        std::uint16_t v;
        std::memcpy(&v, image.bytes.data() + 2 * sample, sizeof v);
        value = static_cast<std::uint8_t>((2u * v + 257u) / 514u);
      } else {
        value = image.bytes[sample];
      }
      out.pixels[3 * i + k] = value;
    }
  }
  return out;
}

}  // namespace

Result<RgbImage> ReadRgbImage(const std::string& path) {
  const Result<ImageSize> kind = ReadImageSize(path);
  if (!kind.ok()) return kind.error();
  Result<DecodedImage> decoded =
      MakeError(ErrorCode::kDataLoss, path + ": not a PNG, JPEG or TIFF image");
  switch (kind->format) {
    case ImageFormat::kPng:
      decoded = ReadPng(path);
      break;
    case ImageFormat::kJpeg:
      decoded = ReadJpeg(path);
      break;
    case ImageFormat::kTiff:
      decoded = ReadTiff(path);
      break;
    case ImageFormat::kOther:
      break;
  }
  if (!decoded.ok()) return decoded.error();
  return ToRgb(*decoded, path);
}

Status WriteRgbPng(const RgbImage& image, const std::string& path) {
  if (!image.valid()) {
    return MakeError(ErrorCode::kInvalidArgument, path + ": image buffer does not match its size");
  }
  DecodedImage rgb;
  rgb.width = image.width;
  rgb.height = image.height;
  rgb.channels = 3;
  rgb.bits_per_sample = 8;
  rgb.bytes = image.pixels;
  Result<std::string> encoded = EncodePng(rgb, 1);
  if (!encoded.ok()) return encoded.error();
  // Written beside the target and renamed: readers never see a half-written image.
  return WriteFileAtomically(path, *encoded);
}

}  // namespace hpose
