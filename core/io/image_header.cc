#include "core/io/image_header.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>

#include "core/io/input_file.h"

namespace hpose {
namespace {

// Enough for a PNG's IHDR and a TIFF's first IFD in every file we write or meet; JPEG SOF
// markers come after the APP segments (EXIF thumbnails can be large).
constexpr std::size_t kHeadBytes = 256 * 1024;

std::uint32_t Read32(const std::string& b, std::size_t at, bool big_endian) {
  const auto* p = reinterpret_cast<const unsigned char*>(b.data() + at);
  return big_endian ? (std::uint32_t{p[0]} << 24 | std::uint32_t{p[1]} << 16 |
                       std::uint32_t{p[2]} << 8 | p[3])
                    : (std::uint32_t{p[3]} << 24 | std::uint32_t{p[2]} << 16 |
                       std::uint32_t{p[1]} << 8 | p[0]);
}

std::uint32_t Read16(const std::string& b, std::size_t at, bool big_endian) {
  const auto* p = reinterpret_cast<const unsigned char*>(b.data() + at);
  return big_endian ? (std::uint32_t{p[0]} << 8 | p[1]) : (std::uint32_t{p[1]} << 8 | p[0]);
}

Error Truncated(const std::string& path, const char* format) {
  return MakeError(ErrorCode::kDataLoss,
                   path + ": truncated or corrupt " + std::string(format) + " header");
}

// Sides above INT32_MAX are clamped: they are refused as too large anyway.
int Side(std::uint32_t v) { return v > 0x7fffffffu ? 0x7fffffff : static_cast<int>(v); }

Result<ImageSize> PngSize(const std::string& head, const std::string& path) {
  // Signature (8), IHDR length (4) and type (4), width (4), height (4).
  if (head.size() < 24 || head.compare(12, 4, "IHDR") != 0) return Truncated(path, "PNG");
  return ImageSize{true, Side(Read32(head, 16, true)), Side(Read32(head, 20, true))};
}

// `count` bytes of the file from `offset`, or fewer at its end.
std::string ReadFileBytes(const std::string& path, std::uint64_t offset, std::size_t count) {
  std::ifstream in(path, std::ios::binary);
  std::string bytes(count, '\0');
  if (!in.seekg(static_cast<std::streamoff>(offset))) return std::string();
  in.read(bytes.data(), static_cast<std::streamsize>(count));
  bytes.resize(static_cast<std::size_t>(std::max<std::streamsize>(in.gcount(), 0)));
  return bytes;
}

// The first image file directory (its entry count and 12-byte entries). Most writers put it
// in the head of the file; some (PCL's grabber, VTK) after the pixels, where it is read alone.
Result<std::string> TiffDirectory(const std::string& head, std::uint32_t ifd, bool big,
                                  const std::string& path) {
  if (ifd < 8) return Truncated(path, "TIFF");
  std::string count =
      std::uint64_t{ifd} + 2 <= head.size() ? head.substr(ifd, 2) : ReadFileBytes(path, ifd, 2);
  if (count.size() < 2) return Truncated(path, "TIFF");
  const std::size_t bytes = 2 + 12 * static_cast<std::size_t>(Read16(count, 0, big));
  std::string directory =
      ifd + bytes <= head.size() ? head.substr(ifd, bytes) : ReadFileBytes(path, ifd, bytes);
  if (directory.size() < bytes) return Truncated(path, "TIFF");
  return directory;
}

Result<ImageSize> TiffSize(const std::string& head, const std::string& path) {
  const bool big = head[0] == 'M';
  const std::uint32_t magic = Read16(head, 2, big);
  if (magic == 43)
    return MakeError(ErrorCode::kInvalidArgument, path + ": BigTIFF is not supported");
  if (magic != 42) return ImageSize{};  // not a TIFF after all.
  Result<std::string> directory = TiffDirectory(head, Read32(head, 4, big), big, path);
  if (!directory.ok()) return directory.error();
  const std::string& d = *directory;
  const std::uint32_t entries = Read16(d, 0, big);
  ImageSize size{true, -1, -1};
  for (std::uint32_t i = 0; i < entries; ++i) {
    const std::size_t at = 2 + 12 * static_cast<std::size_t>(i);
    const std::uint32_t tag = Read16(d, at, big);
    if (tag != 256 && tag != 257) continue;
    const std::uint32_t type = Read16(d, at + 2, big);
    const std::uint32_t value = type == 3   ? Read16(d, at + 8, big)
                                : type == 4 ? Read32(d, at + 8, big)
                                            : 0;
    if (value == 0) return Truncated(path, "TIFF");
    (tag == 256 ? size.width : size.height) = Side(value);
  }
  if (size.width < 0 || size.height < 0) return Truncated(path, "TIFF");
  return size;
}

Result<ImageSize> JpegSize(const std::string& head, const std::string& path) {
  std::size_t at = 2;
  while (at + 4 <= head.size()) {
    if (static_cast<unsigned char>(head[at]) != 0xFF) return Truncated(path, "JPEG");
    const unsigned marker = static_cast<unsigned char>(head[at + 1]);
    if (marker == 0xFF) {  // fill byte.
      ++at;
      continue;
    }
    const std::uint32_t length = Read16(head, at + 2, true);
    const bool sof =
        marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
    if (sof) {
      if (at + 9 > head.size()) break;
      return ImageSize{true, Side(Read16(head, at + 7, true)), Side(Read16(head, at + 5, true))};
    }
    if (length < 2) return Truncated(path, "JPEG");
    at += 2 + length;
  }
  return Truncated(path, "JPEG");  // no frame header within the first kHeadBytes.
}

}  // namespace

Result<ImageSize> ReadImageSize(const std::string& path) {
  Result<std::uint64_t> file = CheckInputFile(path);
  if (!file.ok()) return file.error();
  Result<std::string> head = ReadFileHead(path, kHeadBytes);
  if (!head.ok()) return head.error();
  const std::string& h = *head;
  static const char kPng[] = "\x89PNG\r\n\x1a\n";
  // A known size with the format it was read from.
  const auto as = [](Result<ImageSize> size, ImageFormat format) {
    if (size.ok() && size->known) size->format = format;
    return size;
  };
  if (h.size() >= 8 && h.compare(0, 8, kPng, 8) == 0)
    return as(PngSize(h, path), ImageFormat::kPng);
  if (h.size() >= 8 && (h.compare(0, 2, "II") == 0 || h.compare(0, 2, "MM") == 0)) {
    return as(TiffSize(h, path), ImageFormat::kTiff);
  }
  if (h.size() >= 3 && static_cast<unsigned char>(h[0]) == 0xFF &&
      static_cast<unsigned char>(h[1]) == 0xD8 && static_cast<unsigned char>(h[2]) == 0xFF) {
    return as(JpegSize(h, path), ImageFormat::kJpeg);
  }
  return ImageSize{};
}

Status CheckImageSize(const std::string& path, int max_side) {
  Result<ImageSize> size = ReadImageSize(path);
  if (!size.ok()) return size.error();
  if (!size->known) return Status::Ok();
  if (size->width < 1 || size->height < 1 || size->width > max_side || size->height > max_side) {
    return MakeError(ErrorCode::kOutOfRange,
                     path + ": the image is " + std::to_string(size->width) + "x" +
                         std::to_string(size->height) + " px; sides must be within [1, " +
                         std::to_string(max_side) + "] px");
  }
  return Status::Ok();
}

}  // namespace hpose
