#include "core/io/tiff_reader.h"

#include <tiffio.h>

#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

namespace hpose {
namespace {

// libtiff's errors go here instead of standard error; the first one explains a failure best.
struct TiffMessages {
  char first_error[256] = {};
};

int OnTiffError(TIFF*, void* user_data, const char* module, const char* format, va_list args) {
  auto* messages = static_cast<TiffMessages*>(user_data);
  if (messages->first_error[0] == '\0') {
    char text[200] = {};
    std::vsnprintf(text, sizeof(text), format, args);
    std::snprintf(messages->first_error, sizeof(messages->first_error), "%s%s%s",
                  module ? module : "", module ? ": " : "", text);
  }
  return 1;  // handled: libtiff does not print it.
}

// Warnings (unknown tags and the like) do not stop the decoding.
int OnTiffWarning(TIFF*, void*, const char*, const char*, va_list) { return 1; }

struct TiffCloser {
  void operator()(TIFF* tiff) const { TIFFClose(tiff); }
};
struct TiffOptionsFreer {
  void operator()(TIFFOpenOptions* options) const { TIFFOpenOptionsFree(options); }
};

template <typename T>
T Field(TIFF* tiff, ttag_t tag) {
  T value = 0;
  TIFFGetFieldDefaulted(tiff, tag, &value);
  return value;
}

// Copies the part of a decoded tile that lies inside the image.
void CopyTile(const std::vector<std::uint8_t>& tile, std::uint32_t tile_width,
              std::uint32_t tile_height, std::uint32_t x, std::uint32_t y, size_t pixel_bytes,
              DecodedImage* image) {
  const std::uint32_t columns = std::min<std::uint32_t>(tile_width, image->width - x);
  const std::uint32_t rows = std::min<std::uint32_t>(tile_height, image->height - y);
  for (std::uint32_t r = 0; r < rows; ++r) {
    std::memcpy(image->bytes.data() + (y + r) * image->RowBytes() + x * pixel_bytes,
                tile.data() + static_cast<size_t>(r) * tile_width * pixel_bytes,
                columns * pixel_bytes);
  }
}

}  // namespace

Result<DecodedImage> ReadTiff(const std::string& path, int max_side) {
  // A regular file (a FIFO would block) whose first IFD announces a decodable size.
  if (Status size = CheckImageSize(path, max_side); !size.ok()) return size.error();
  TiffMessages messages;
  std::unique_ptr<TIFFOpenOptions, TiffOptionsFreer> options(TIFFOpenOptionsAlloc());
  if (!options) return MakeError(ErrorCode::kInternal, path + ": cannot set up libtiff");
  TIFFOpenOptionsSetErrorHandlerExtR(options.get(), OnTiffError, &messages);
  TIFFOpenOptionsSetWarningHandlerExtR(options.get(), OnTiffWarning, &messages);
  std::unique_ptr<TIFF, TiffCloser> tiff(TIFFOpenExt(path.c_str(), "r", options.get()));
  auto data_loss = [&](const std::string& what) {
    return MakeError(ErrorCode::kDataLoss, path + ": " + what +
                                               (messages.first_error[0] != '\0'
                                                    ? " (" + std::string(messages.first_error) + ")"
                                                    : std::string()));
  };
  if (!tiff) return data_loss("not a readable TIFF image");

  const auto width = Field<std::uint32_t>(tiff.get(), TIFFTAG_IMAGEWIDTH);
  const auto height = Field<std::uint32_t>(tiff.get(), TIFFTAG_IMAGELENGTH);
  const auto channels = Field<std::uint16_t>(tiff.get(), TIFFTAG_SAMPLESPERPIXEL);
  const auto bits = Field<std::uint16_t>(tiff.get(), TIFFTAG_BITSPERSAMPLE);
  const auto format = Field<std::uint16_t>(tiff.get(), TIFFTAG_SAMPLEFORMAT);
  const auto planar = Field<std::uint16_t>(tiff.get(), TIFFTAG_PLANARCONFIG);
  std::uint16_t photometric = PHOTOMETRIC_MINISBLACK;
  TIFFGetField(tiff.get(), TIFFTAG_PHOTOMETRIC, &photometric);
  if (width == 0 || height == 0) return data_loss("TIFF image of no pixels");
  if (width > static_cast<std::uint32_t>(max_side) ||
      height > static_cast<std::uint32_t>(max_side)) {
    return MakeError(ErrorCode::kOutOfRange, path + ": " + std::to_string(width) + "x" +
                                                 std::to_string(height) + " px, at most " +
                                                 std::to_string(max_side) + " px per side");
  }
  const std::string layout = std::to_string(channels) + " channel(s) of " + std::to_string(bits) +
                             "-bit " +
                             (format == SAMPLEFORMAT_IEEEFP ? "float"
                              : format == SAMPLEFORMAT_INT  ? "signed"
                                                            : "unsigned") +
                             " samples";
  if (channels < 1 || channels > 4 || (bits != 8 && bits != 16) || format != SAMPLEFORMAT_UINT ||
      photometric == PHOTOMETRIC_PALETTE || photometric == PHOTOMETRIC_YCBCR ||
      (channels > 1 && planar != PLANARCONFIG_CONTIG)) {
    return MakeError(
        ErrorCode::kInvalidArgument,
        path + ": unsupported TIFF layout: " + layout +
            (photometric == PHOTOMETRIC_PALETTE ? ", palette" : "") +
            (photometric == PHOTOMETRIC_YCBCR ? ", YCbCr" : "") +
            (channels > 1 && planar != PLANARCONFIG_CONTIG ? ", separate planes" : "") +
            " (8- or 16-bit unsigned grey, RGB or RGBA are read)");
  }

  DecodedImage image;
  image.width = static_cast<int>(width);
  image.height = static_cast<int>(height);
  image.channels = channels;
  image.bits_per_sample = bits;
  image.bytes.resize(image.RowBytes() * height);
  const size_t pixel_bytes = static_cast<size_t>(channels) * (bits / 8);
  if (TIFFIsTiled(tiff.get())) {
    const auto tile_width = Field<std::uint32_t>(tiff.get(), TIFFTAG_TILEWIDTH);
    const auto tile_height = Field<std::uint32_t>(tiff.get(), TIFFTAG_TILELENGTH);
    const tmsize_t tile_bytes = TIFFTileSize(tiff.get());
    if (tile_width == 0 || tile_height == 0 ||
        tile_bytes != static_cast<tmsize_t>(tile_width * pixel_bytes * tile_height)) {
      return data_loss("inconsistent TIFF tiles");
    }
    std::vector<std::uint8_t> tile(static_cast<size_t>(tile_bytes));
    for (std::uint32_t y = 0; y < height; y += tile_height) {
      for (std::uint32_t x = 0; x < width; x += tile_width) {
        if (TIFFReadTile(tiff.get(), tile.data(), x, y, 0, 0) < 0) {
          return data_loss("cannot decode the TIFF (corrupt or truncated)");
        }
        CopyTile(tile, tile_width, tile_height, x, y, pixel_bytes, &image);
      }
    }
  } else {
    if (TIFFScanlineSize(tiff.get()) != static_cast<tmsize_t>(image.RowBytes())) {
      return data_loss("inconsistent TIFF rows");
    }
    for (std::uint32_t y = 0; y < height; ++y) {
      if (TIFFReadScanline(tiff.get(), image.bytes.data() + y * image.RowBytes(), y, 0) < 0) {
        return data_loss("cannot decode the TIFF (corrupt or truncated)");
      }
    }
  }
  return image;
}

}  // namespace hpose
