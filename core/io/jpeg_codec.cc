#include "core/io/jpeg_codec.h"

// jpeglib.h uses FILE and size_t without including their headers.
#include <cstddef>
#include <cstdio>
#include <cstdlib>

#include <jpeglib.h>
// After jpeglib.h: the message codes (JWRN_...).
#include <jerror.h>

#include <csetjmp>
#include <memory>

#include "core/io/atomic_file.h"

namespace hpose {
namespace {

// libjpeg reports a fatal error through error_exit, which must not return: OnJpegError longjmps
// back into the function that called setjmp (DecodeInto, EncodeInto below). Those functions and
// libjpeg's own frames hold only plain C data, so the jump skips no destructor; every C++ object
// lives in their callers.
struct JpegErrors {
  jpeg_error_mgr manager;  // first: libjpeg's pointer to it points to the whole struct.
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
  bool corrupt;  // a warning said the pixels are damaged (the first one's text is in message).
};

void OnJpegError(j_common_ptr cinfo) {
  auto* errors = reinterpret_cast<JpegErrors*>(cinfo->err);
  (*cinfo->err->format_message)(cinfo, errors->message);
  std::longjmp(errors->jump, 1);
}

// Whether a warning of libjpeg's means wrong pixels: a premature end (after which libjpeg fills
// the rest of the image with grey), bad entropy codes, lost synchronisation, an inconsistent
// progression. Others leave the pixels as the encoder meant them: stray bytes between markers
// (which some cameras write, and OpenCV's reader accepts), an unknown JFIF revision or colour
// transform, a damaged ICC profile.
bool DamagesPixels(int code) {
  switch (code) {
    case JWRN_JPEG_EOF:
    case JWRN_HIT_MARKER:
    case JWRN_HUFF_BAD_CODE:
    case JWRN_ARITH_BAD_CODE:
    case JWRN_MUST_RESYNC:
    case JWRN_BOGUS_PROGRESSION:
    case JWRN_NOT_SEQUENTIAL:
      return true;
    default:
      return false;
  }
}

// Level -1 is a warning, higher levels are trace messages. Nothing is printed.
void OnJpegMessage(j_common_ptr cinfo, int level) {
  auto* errors = reinterpret_cast<JpegErrors*>(cinfo->err);
  if (level < 0 && !errors->corrupt && DamagesPixels(cinfo->err->msg_code)) {
    errors->corrupt = true;
    (*cinfo->err->format_message)(cinfo, errors->message);
  }
}

void InitErrors(JpegErrors* errors) {
  jpeg_std_error(&errors->manager);
  errors->manager.error_exit = OnJpegError;
  errors->manager.emit_message = OnJpegMessage;
  errors->message[0] = '\0';
  errors->corrupt = false;
}

// Why a decoding stopped without an error from libjpeg.
enum class Refusal { kNone, kTooLarge, kCmyk };

// Reads the header and every row into `out`. False after a libjpeg error (errors->message).
bool DecodeInto(jpeg_decompress_struct* cinfo, JpegErrors* errors, const std::string& bytes,
                int max_side, DecodedImage* out, Refusal* refusal) {
  if (setjmp(errors->jump)) return false;
  jpeg_create_decompress(cinfo);
  jpeg_mem_src(cinfo, reinterpret_cast<const unsigned char*>(bytes.data()),
               static_cast<unsigned long>(bytes.size()));
  jpeg_read_header(cinfo, TRUE);
  if (cinfo->image_width > static_cast<JDIMENSION>(max_side) ||
      cinfo->image_height > static_cast<JDIMENSION>(max_side)) {
    *refusal = Refusal::kTooLarge;
    return true;
  }
  if (cinfo->jpeg_color_space == JCS_CMYK || cinfo->jpeg_color_space == JCS_YCCK) {
    *refusal = Refusal::kCmyk;
    return true;
  }
  cinfo->out_color_space = cinfo->num_components == 1 ? JCS_GRAYSCALE : JCS_RGB;
  jpeg_start_decompress(cinfo);
  out->width = static_cast<int>(cinfo->output_width);
  out->height = static_cast<int>(cinfo->output_height);
  out->channels = cinfo->output_components;
  out->bits_per_sample = 8;
  out->bytes.resize(out->RowBytes() * static_cast<size_t>(out->height));
  while (cinfo->output_scanline < cinfo->output_height) {
    JSAMPROW row = out->bytes.data() + out->RowBytes() * cinfo->output_scanline;
    jpeg_read_scanlines(cinfo, &row, 1);
  }
  jpeg_finish_decompress(cinfo);
  return true;
}

// Encodes `image` into libjpeg's buffer (*buffer, *size; malloc'd, freed by the caller). False
// after a libjpeg error (errors->message).
bool EncodeInto(jpeg_compress_struct* cinfo, JpegErrors* errors, const DecodedImage& image,
                int quality, unsigned char** buffer, unsigned long* size) {
  if (setjmp(errors->jump)) return false;
  jpeg_create_compress(cinfo);
  jpeg_mem_dest(cinfo, buffer, size);
  cinfo->image_width = static_cast<JDIMENSION>(image.width);
  cinfo->image_height = static_cast<JDIMENSION>(image.height);
  cinfo->input_components = image.channels;
  cinfo->in_color_space = image.channels == 1 ? JCS_GRAYSCALE : JCS_RGB;
  jpeg_set_defaults(cinfo);
  jpeg_set_quality(cinfo, quality, TRUE);
  jpeg_start_compress(cinfo, TRUE);
  while (cinfo->next_scanline < cinfo->image_height) {
    // libjpeg's interface wants non-const rows; it only reads them.
    JSAMPROW row =
        const_cast<JSAMPROW>(image.bytes.data() + image.RowBytes() * cinfo->next_scanline);
    jpeg_write_scanlines(cinfo, &row, 1);
  }
  jpeg_finish_compress(cinfo);
  return true;
}

}  // namespace

Result<DecodedImage> DecodeJpeg(const std::string& bytes, const std::string& name, int max_side) {
  JpegErrors errors;
  InitErrors(&errors);
  jpeg_decompress_struct cinfo{};
  cinfo.err = &errors.manager;
  DecodedImage out;
  Refusal refusal = Refusal::kNone;
  const bool decoded = DecodeInto(&cinfo, &errors, bytes, max_side, &out, &refusal);
  const JDIMENSION width = cinfo.image_width, height = cinfo.image_height;
  jpeg_destroy_decompress(&cinfo);
  if (!decoded) {
    return MakeError(ErrorCode::kDataLoss,
                     name + ": not a decodable JPEG image (" + errors.message + ")");
  }
  if (refusal == Refusal::kTooLarge) {
    return MakeError(ErrorCode::kOutOfRange, name + ": " + std::to_string(width) + "x" +
                                                 std::to_string(height) + " px, at most " +
                                                 std::to_string(max_side) + " px per side");
  }
  if (refusal == Refusal::kCmyk) {
    return MakeError(ErrorCode::kInvalidArgument,
                     name + ": a CMYK JPEG image (hpose reads grey and colour ones)");
  }
  if (errors.corrupt) {
    return MakeError(ErrorCode::kDataLoss,
                     name + ": corrupt or truncated JPEG data (" + errors.message + ")");
  }
  return out;
}

Result<DecodedImage> ReadJpeg(const std::string& path, int max_side) {
  const Status size = CheckImageSize(path, max_side);
  if (!size.ok()) return size.error();
  Result<std::string> bytes = ReadFile(path);
  if (!bytes.ok()) return bytes.error();
  return DecodeJpeg(*bytes, path, max_side);
}

Result<std::string> EncodeJpeg(const DecodedImage& image, int quality) {
  if (image.width <= 0 || image.height <= 0 || (image.channels != 1 && image.channels != 3) ||
      image.bits_per_sample != 8 ||
      image.bytes.size() != image.RowBytes() * static_cast<size_t>(image.height)) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "JPEG encoding: need 8-bit grey or RGB pixels matching the image's size");
  }
  if (quality < 1 || quality > 100) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "JPEG encoding: quality " + std::to_string(quality) + " outside 1-100");
  }
  JpegErrors errors;
  InitErrors(&errors);
  jpeg_compress_struct cinfo{};
  cinfo.err = &errors.manager;
  unsigned char* buffer = nullptr;
  unsigned long size = 0;
  const bool encoded = EncodeInto(&cinfo, &errors, image, quality, &buffer, &size);
  jpeg_destroy_compress(&cinfo);
  const std::unique_ptr<unsigned char, void (*)(void*)> owned(buffer, std::free);
  if (!encoded) {
    return MakeError(ErrorCode::kInternal,
                     std::string("JPEG encoding failed (") + errors.message + ")");
  }
  return std::string(reinterpret_cast<const char*>(buffer), size);
}

}  // namespace hpose
