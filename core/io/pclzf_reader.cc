#include "core/io/pclzf_reader.h"

#include <cstring>
#include <utility>

#include "core/io/atomic_file.h"
#include "core/io/cloud_text.h"
#include "core/io/image_header.h"
#include "core/io/input_file.h"
#include "core/io/lzf.h"

namespace hpose {
namespace {

// "PCLZF", width and height (uint32), image type (16 characters, space padded), packed and
// unpacked sizes (uint32), all little-endian.
constexpr std::size_t kHeaderBytes = 5 + 4 + 4 + 16 + 4 + 4;

std::uint32_t Uint32At(const std::string& bytes, std::size_t at) {
  const auto* p = reinterpret_cast<const unsigned char*>(bytes.data() + at);
  return std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 |
         std::uint32_t{p[3]} << 24;
}

// The text between <name> and </name> in `text`; false when either is missing.
bool ElementText(const std::string& text, const std::string& name, std::string* inner) {
  const std::string open = "<" + name + ">";
  const std::string close = "</" + name + ">";
  const std::size_t a = text.find(open);
  if (a == std::string::npos) return false;
  const std::size_t b = text.find(close, a + open.size());
  if (b == std::string::npos) return false;
  *inner = text.substr(a + open.size(), b - a - open.size());
  return true;
}

}  // namespace

Result<PclzfDepth16> ReadPclzfDepth16(const std::string& path) {
  Result<std::uint64_t> size = CheckInputFile(path);
  if (!size.ok()) return size.error();
  Result<std::string> file = ReadFile(path);
  if (!file.ok()) return file.error();
  const std::string& f = *file;
  if (f.size() < kHeaderBytes || f.compare(0, 5, "PCLZF") != 0) {
    return MakeError(ErrorCode::kDataLoss, path + ": not a PCL-LZF image (no PCLZF header)");
  }
  const std::uint32_t width = Uint32At(f, 5);
  const std::uint32_t height = Uint32At(f, 9);
  std::string type = f.substr(13, 16);
  type.erase(type.find_last_not_of(std::string(" \0", 2)) + 1);
  const std::uint32_t packed = Uint32At(f, 29);
  const std::uint32_t unpacked = Uint32At(f, 33);
  if (type != "depth16") {
    return MakeError(ErrorCode::kInvalidArgument,
                     path + ": not a 16-bit PCL-LZF depth image (type '" + type + "')");
  }
  if (width < 1 || height < 1 || width > static_cast<std::uint32_t>(kMaxImageSide) ||
      height > static_cast<std::uint32_t>(kMaxImageSide)) {
    return MakeError(ErrorCode::kOutOfRange, path + ": the image is " + std::to_string(width) +
                                                 "x" + std::to_string(height) +
                                                 " px; sides must be within [1, " +
                                                 std::to_string(kMaxImageSide) + "] px");
  }
  const std::uint64_t need = std::uint64_t{width} * height * 2;
  if (unpacked != need || packed > f.size() - kHeaderBytes) {
    return MakeError(ErrorCode::kDataLoss, path + ": corrupt or truncated PCL-LZF image (" +
                                               std::to_string(packed) + " packed bytes of " +
                                               std::to_string(f.size() - kHeaderBytes) +
                                               " present, " + std::to_string(unpacked) +
                                               " unpacked for " + std::to_string(need) + ")");
  }
  PclzfDepth16 image;
  image.width = static_cast<int>(width);
  image.height = static_cast<int>(height);
  image.values.resize(static_cast<std::size_t>(width) * height);
  if (!LzfDecompress(reinterpret_cast<const std::uint8_t*>(f.data()) + kHeaderBytes, packed,
                     reinterpret_cast<std::uint8_t*>(image.values.data()), need)) {
    return MakeError(ErrorCode::kDataLoss, path + ": corrupt PCL-LZF image data (LZF)");
  }
  return image;
}

Result<PclzfDepthCamera> ReadPclzfDepthCamera(const std::string& xml_path) {
  Result<std::uint64_t> size = CheckInputFile(xml_path);
  if (!size.ok()) return size.error();
  if (*size > 1 << 20) {
    return MakeError(ErrorCode::kDataLoss, xml_path + ": too large for camera parameters");
  }
  Result<std::string> text = ReadFile(xml_path);
  if (!text.ok()) return text.error();
  std::string depth;
  if (!ElementText(*text, "depth", &depth)) {
    return MakeError(ErrorCode::kDataLoss, xml_path + ": no <depth> camera parameters");
  }
  PclzfDepthCamera camera;
  const std::pair<const char*, double*> fields[] = {
      {"focal_length_x", &camera.focal_length_x},
      {"focal_length_y", &camera.focal_length_y},
      {"principal_point_x", &camera.principal_point_x},
      {"principal_point_y", &camera.principal_point_y},
      {"z_multiplication_factor", &camera.z_multiplication_factor}};
  for (const auto& [name, value] : fields) {
    std::string inner;
    if (!ElementText(depth, name, &inner)) {
      return MakeError(ErrorCode::kDataLoss, xml_path + ": <depth> has no <" + name + ">");
    }
    const std::vector<std::string> words = SplitWords(inner, 0, inner.size());
    if (words.size() != 1 || !ParseDouble(words[0], value)) {
      return MakeError(ErrorCode::kDataLoss,
                       xml_path + ": <depth><" + name + "> '" + inner + "' is not a number");
    }
  }
  return camera;
}

}  // namespace hpose
