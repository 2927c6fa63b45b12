#include "core/io/png_codec.h"

#include <png.h>
#include <zlib.h>

#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <new>
#include <vector>

namespace hpose {
namespace {

// libpng reports errors by calling OnPngError, which longjmps back into the function that
// called setjmp. Those functions (ReadHeader, ReadRows, WriteRows below) and libpng's own frames
// hold only plain C data, so the jump skips no destructor; every C++ object lives in the callers.
struct PngCallState {
  char message[256] = {};         // libpng's message of the error that ended the call.
  std::string* output = nullptr;  // encoding: where the bytes go.
};

void OnPngError(png_structp png, png_const_charp message) {
  auto* state = static_cast<PngCallState*>(png_get_error_ptr(png));
  std::snprintf(state->message, sizeof(state->message), "%s", message);
  png_longjmp(png, 1);
}

// Warnings (e.g. a damaged ancillary chunk, which libpng skips) do not stop the decoding.
void OnPngWarning(png_structp, png_const_charp) {}

bool HostIsLittleEndian() {
  const std::uint16_t one = 1;
  unsigned char first = 0;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

struct PngLayout {
  png_uint_32 width = 0;
  png_uint_32 height = 0;
  int channels = 0;
  int bit_depth = 0;
  size_t row_bytes = 0;
};

// Reads the header and sets the transformations to plain 8- or 16-bit samples in host order.
bool ReadHeader(png_structp png, png_infop info, std::FILE* file, png_uint_32 max_side,
                PngLayout* layout) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_init_io(png, file);
  png_set_user_limits(png, max_side, max_side);
  png_read_info(png, info);
  const int color_type = png_get_color_type(png, info);
  const int bit_depth = png_get_bit_depth(png, info);
  if (color_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (color_type == PNG_COLOR_TYPE_GRAY && bit_depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  if (bit_depth == 16 && HostIsLittleEndian()) png_set_swap(png);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  layout->width = png_get_image_width(png, info);
  layout->height = png_get_image_height(png, info);
  layout->channels = png_get_channels(png, info);
  layout->bit_depth = png_get_bit_depth(png, info);
  layout->row_bytes = png_get_rowbytes(png, info);
  return true;
}

// Decodes every row and reads on to the end of the file (so that a truncated file fails).
bool ReadRows(png_structp png, png_infop info, png_bytepp rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_image(png, rows);
  png_read_end(png, info);
  return true;
}

void AppendToOutput(png_structp png, png_bytep data, size_t size) {
  auto* state = static_cast<PngCallState*>(png_get_io_ptr(png));
  bool appended = true;
  try {
    state->output->append(reinterpret_cast<const char*>(data), size);
  } catch (const std::bad_alloc&) {
    appended = false;
  }
  if (!appended) png_error(png, "out of memory for the encoded PNG");
}

void FlushNothing(png_structp) {}

bool WriteRows(png_structp png, png_infop info, PngCallState* state, const DecodedImage& image,
               int compression_level, png_bytepp rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  static constexpr int kColorTypes[] = {PNG_COLOR_TYPE_GRAY, PNG_COLOR_TYPE_GRAY_ALPHA,
                                        PNG_COLOR_TYPE_RGB, PNG_COLOR_TYPE_RGB_ALPHA};
  png_set_write_fn(png, state, AppendToOutput, FlushNothing);
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.width),
               static_cast<png_uint_32>(image.height), image.bits_per_sample,
               kColorTypes[image.channels - 1], PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_set_compression_level(png, compression_level);
  if (compression_level <= 1) {
    // The fastest settings (a recorder writes 30 depth frames a second): one filter for every
    // row instead of trying all five, and run-length matching only.
    png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
    png_set_compression_strategy(png, Z_RLE);
  }
  png_write_info(png, info);
  if (image.bits_per_sample == 16 && HostIsLittleEndian()) png_set_swap(png);
  png_write_image(png, rows);
  png_write_end(png, nullptr);
  return true;
}

// Row pointers into `bytes` (libpng's interface wants non-const rows even when writing; it
// copies each row before transforming it).
std::vector<png_bytep> RowPointers(const std::uint8_t* bytes, size_t row_bytes, int height) {
  std::vector<png_bytep> rows(static_cast<size_t>(height));
  for (int v = 0; v < height; ++v) {
    rows[static_cast<size_t>(v)] = const_cast<png_bytep>(bytes + row_bytes * v);
  }
  return rows;
}

// Owns libpng's read structures and the open file.
class PngReader {
 public:
  PngReader(std::FILE* file, PngCallState* state)
      : file_(file),
        png_(png_create_read_struct(PNG_LIBPNG_VER_STRING, state, OnPngError, OnPngWarning)),
        info_(png_ ? png_create_info_struct(png_) : nullptr) {}
  ~PngReader() {
    if (png_) png_destroy_read_struct(&png_, info_ ? &info_ : nullptr, nullptr);
    std::fclose(file_);
  }
  PngReader(const PngReader&) = delete;
  PngReader& operator=(const PngReader&) = delete;

  bool ok() const { return png_ && info_; }
  png_structp png() const { return png_; }
  png_infop info() const { return info_; }
  std::FILE* file() const { return file_; }

 private:
  std::FILE* file_;
  png_structp png_;
  png_infop info_;
};

}  // namespace

Result<DecodedImage> ReadPng(const std::string& path, int max_side) {
  // A regular file (a FIFO would block) whose header announces a decodable size.
  if (Status size = CheckImageSize(path, max_side); !size.ok()) return size.error();
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file) return MakeError(ErrorCode::kNotFound, path + ": cannot open the file");
  unsigned char signature[8] = {};
  const size_t got = std::fread(signature, 1, sizeof(signature), file);
  if (got != sizeof(signature) || png_sig_cmp(signature, 0, sizeof(signature)) != 0) {
    std::fclose(file);
    return MakeError(ErrorCode::kDataLoss, path + ": not a PNG file (bad signature)");
  }
  std::rewind(file);
  PngCallState state;
  PngReader reader(file, &state);
  if (!reader.ok()) return MakeError(ErrorCode::kInternal, path + ": cannot set up libpng");
  PngLayout layout;
  if (!ReadHeader(reader.png(), reader.info(), reader.file(), static_cast<png_uint_32>(max_side),
                  &layout)) {
    return MakeError(ErrorCode::kDataLoss,
                     path + ": cannot decode the PNG header: " + std::string(state.message));
  }
  DecodedImage image;
  image.width = static_cast<int>(layout.width);
  image.height = static_cast<int>(layout.height);
  image.channels = layout.channels;
  image.bits_per_sample = layout.bit_depth;
  if ((image.bits_per_sample != 8 && image.bits_per_sample != 16) || image.channels < 1 ||
      image.channels > 4 || layout.row_bytes != image.RowBytes()) {
    return MakeError(ErrorCode::kDataLoss, path + ": unsupported PNG layout (" +
                                               std::to_string(image.channels) + " channels of " +
                                               std::to_string(image.bits_per_sample) + " bits)");
  }
  image.bytes.resize(image.RowBytes() * image.height);
  std::vector<png_bytep> rows = RowPointers(image.bytes.data(), image.RowBytes(), image.height);
  if (!ReadRows(reader.png(), reader.info(), rows.data())) {
    return MakeError(
        ErrorCode::kDataLoss,
        path + ": cannot decode the PNG (corrupt or truncated): " + std::string(state.message));
  }
  return image;
}

Result<std::string> EncodePng(const DecodedImage& image, int compression_level) {
  if (image.width <= 0 || image.height <= 0 || image.channels < 1 || image.channels > 4 ||
      (image.bits_per_sample != 8 && image.bits_per_sample != 16) ||
      image.bytes.size() != image.RowBytes() * image.height) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "cannot encode a " + std::to_string(image.width) + "x" +
                         std::to_string(image.height) + " image of " +
                         std::to_string(image.channels) + " channel(s) of " +
                         std::to_string(image.bits_per_sample) + " bits holding " +
                         std::to_string(image.bytes.size()) + " bytes as PNG");
  }
  if (compression_level < 0 || compression_level > 9) {
    return MakeError(ErrorCode::kInvalidArgument, "PNG compression level must be 0 to 9, not " +
                                                      std::to_string(compression_level));
  }
  std::vector<png_bytep> rows = RowPointers(image.bytes.data(), image.RowBytes(), image.height);
  std::string encoded;
  PngCallState state;
  state.output = &encoded;
  png_structp png =
      png_create_write_struct(PNG_LIBPNG_VER_STRING, &state, OnPngError, OnPngWarning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  const bool written =
      png && info && WriteRows(png, info, &state, image, compression_level, rows.data());
  if (png) png_destroy_write_struct(&png, info ? &info : nullptr);
  if (!written) {
    return MakeError(ErrorCode::kInternal, "PNG encoding failed: " + std::string(state.message));
  }
  return encoded;
}

}  // namespace hpose
