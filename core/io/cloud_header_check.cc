#include "core/io/cloud_header_check.h"

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <vector>

#include "core/io/input_file.h"

namespace hpose {
namespace {

// Headers are short; one that does not end within this many bytes is not a cloud header.
constexpr std::size_t kMaxHeaderBytes = 64 * 1024;
// LZF (PCD binary_compressed) expands at most ~90x; anything claiming more is forged.
constexpr std::uint64_t kMaxCompressionRatio = 100;

// Parses a decimal integer (possibly negative) that must fill the whole token.
bool ParseInt(const std::string& token, long long* out) {
  if (token.empty()) return false;
  errno = 0;
  char* end = nullptr;
  *out = std::strtoll(token.c_str(), &end, 10);
  return errno == 0 && end == token.c_str() + token.size();
}

std::vector<std::string> Split(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> tokens;
  std::string t;
  while (in >> t) tokens.push_back(t);
  return tokens;
}

// Checks a count against the limit; `what` names it in the message.
Status CheckCount(const std::string& path, const std::string& what, long long count) {
  if (count < 0) return FileDataLoss(path, what + " " + std::to_string(count) + " is negative");
  if (static_cast<std::uint64_t>(count) > kMaxCloudFilePoints) {
    return MakeError(ErrorCode::kOutOfRange,
                     path + ": " + what + " " + std::to_string(count) + " is more than the " +
                         std::to_string(kMaxCloudFilePoints) + " points read at most");
  }
  return Status::Ok();
}

Status ShortData(const std::string& path, std::uint64_t points, std::uint64_t need,
                 std::uint64_t have) {
  return FileDataLoss(path, "the header announces " + std::to_string(points) + " points (" +
                                std::to_string(need) + " bytes at least) but only " +
                                std::to_string(have) + " bytes follow it");
}

Status CheckPcd(const std::string& path, const std::string& head, std::uint64_t file_bytes) {
  std::istringstream in(head);
  std::string line;
  std::uint64_t point_step = 0, values = 0;
  std::vector<long long> sizes, counts;
  long long width = -1, height = 1, points = -1;
  std::string data;
  std::size_t data_offset = 0;
  while (std::getline(in, line)) {
    if (in.eof()) break;  // a line cut by the head's end is not a header line.
    const std::vector<std::string> t = Split(line);
    if (t.empty() || t[0][0] == '#') continue;
    auto numbers = [&](std::vector<long long>* out) -> Status {
      out->clear();
      for (std::size_t i = 1; i < t.size(); ++i) {
        long long v;
        if (!ParseInt(t[i], &v) || v < 1 || v > 1 << 20) {
          return FileDataLoss(path,
                              "PCD " + t[0] + " value '" + t[i] + "' is not a positive integer");
        }
        out->push_back(v);
      }
      return Status::Ok();
    };
    Status st;
    long long* scalar = t[0] == "WIDTH"    ? &width
                        : t[0] == "HEIGHT" ? &height
                        : t[0] == "POINTS" ? &points
                                           : nullptr;
    if (t[0] == "SIZE") st = numbers(&sizes);
    if (t[0] == "COUNT") st = numbers(&counts);
    if (!st.ok()) return st;
    if (scalar != nullptr) {
      if (t.size() != 2 || !ParseInt(t[1], scalar)) {
        return FileDataLoss(path, "PCD " + t[0] + " is not an integer");
      }
      st = CheckCount(path, "PCD " + t[0], *scalar);
      if (!st.ok()) return st;
    }
    if (t[0] == "DATA") {
      data = t.size() > 1 ? t[1] : "";
      data_offset = static_cast<std::size_t>(in.tellg());
      break;
    }
  }
  if (data.empty())
    return FileDataLoss(path, "no DATA line within the first 64 KiB (not a PCD header)");
  if (counts.empty()) counts.assign(sizes.size(), 1);
  if (counts.size() != sizes.size())
    return FileDataLoss(path, "PCD SIZE and COUNT differ in length");
  for (std::size_t i = 0; i < sizes.size(); ++i) {
    point_step += static_cast<std::uint64_t>(sizes[i]) * counts[i];
    values += static_cast<std::uint64_t>(counts[i]);
  }
  if (points < 0) points = width < 0 ? 0 : width * height;
  if (width >= 0 && static_cast<std::uint64_t>(width) * height > kMaxCloudFilePoints) {
    return CheckCount(path, "PCD WIDTH x HEIGHT", width * height);
  }
  const std::uint64_t n = static_cast<std::uint64_t>(points);
  const std::uint64_t remaining = file_bytes - std::min<std::uint64_t>(file_bytes, data_offset);
  if (data == "ascii") {
    // Each value takes a digit and a separator at least (the last may lack its newline).
    if (n > 0 && n * values * 2 > remaining + 1)
      return ShortData(path, n, n * values * 2 - 1, remaining);
  } else if (data == "binary") {
    if (n * point_step > remaining) return ShortData(path, n, n * point_step, remaining);
  } else if (data == "binary_compressed") {
    if (remaining < 8) return ShortData(path, n, 8, remaining);
    const auto* p = reinterpret_cast<const unsigned char*>(head.data() + data_offset);
    if (data_offset + 8 > head.size())
      return FileDataLoss(path, "truncated binary_compressed sizes");
    const std::uint64_t compressed = p[0] | p[1] << 8 | p[2] << 16 | std::uint64_t{p[3]} << 24;
    const std::uint64_t uncompressed = p[4] | p[5] << 8 | p[6] << 16 | std::uint64_t{p[7]} << 24;
    if (compressed > remaining - 8) {
      return FileDataLoss(path, "binary_compressed data claims " + std::to_string(compressed) +
                                    " compressed bytes but only " + std::to_string(remaining - 8) +
                                    " follow");
    }
    if (n > 0 && uncompressed != n * point_step) {
      return FileDataLoss(path, "binary_compressed data unpacks to " +
                                    std::to_string(uncompressed) + " bytes, but " +
                                    std::to_string(n) + " points of " + std::to_string(point_step) +
                                    " bytes need " + std::to_string(n * point_step));
    }
    if (uncompressed > kMaxCompressionRatio * (compressed + 1)) {
      return FileDataLoss(path, "binary_compressed data claims to unpack " +
                                    std::to_string(compressed) + " bytes into " +
                                    std::to_string(uncompressed) + " (more than LZF can)");
    }
  } else {
    return FileDataLoss(path, "unknown PCD DATA kind '" + data + "'");
  }
  return Status::Ok();
}

int PlyTypeBytes(const std::string& type) {
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
  if (type == "int" || type == "uint" || type == "float" || type == "int32" || type == "uint32" ||
      type == "float32") {
    return 4;
  }
  if (type == "double" || type == "float64") return 8;
  return 0;
}

Status CheckPly(const std::string& path, const std::string& head, std::uint64_t file_bytes) {
  std::istringstream in(head);
  std::string line;
  std::string format;
  struct Element {
    std::string name;
    std::uint64_t count = 0;
    std::uint64_t min_bytes = 0;  // per record (a list counts its length field only).
    std::uint64_t values = 0;     // per record, lists counted as one.
  };
  std::vector<Element> elements;
  bool ended = false;
  std::size_t data_offset = 0;
  while (std::getline(in, line)) {
    if (in.eof()) break;
    const std::vector<std::string> t = Split(line);
    if (t.empty()) continue;
    if (t[0] == "format" && t.size() >= 2) format = t[1];
    if (t[0] == "element") {
      long long count;
      if (t.size() != 3 || !ParseInt(t[2], &count)) {
        return FileDataLoss(path, "PLY element line '" + line + "' has no integer count");
      }
      const Status st = CheckCount(path, "PLY element '" + t[1] + "' count", count);
      if (!st.ok()) return st;
      elements.push_back(Element{t[1], static_cast<std::uint64_t>(count), 0, 0});
    }
    if (t[0] == "property" && !elements.empty() && t.size() >= 3) {
      const int bytes = PlyTypeBytes(t[1] == "list" ? t[2] : t[1]);
      if (bytes == 0) return FileDataLoss(path, "PLY property type '" + t[1] + "' is unknown");
      elements.back().min_bytes += static_cast<std::uint64_t>(bytes);
      elements.back().values += 1;
    }
    if (t[0] == "end_header") {
      ended = true;
      data_offset = static_cast<std::size_t>(in.tellg());
      break;
    }
  }
  if (!ended) return FileDataLoss(path, "no end_header within the first 64 KiB (not a PLY header)");
  const std::uint64_t remaining = file_bytes - std::min<std::uint64_t>(file_bytes, data_offset);
  std::uint64_t need = 0, points = 0;
  for (const Element& e : elements) {
    need += e.count * (format == "ascii" ? 2 * e.values : e.min_bytes);
    if (e.name == "vertex") points = e.count;
  }
  if (format == "ascii" && need > 0) need -= 1;
  if (need > remaining) return ShortData(path, points, need, remaining);
  return Status::Ok();
}

}  // namespace

Status CheckCloudFileHeader(const std::string& path, const std::string& ext,
                            std::uint64_t file_bytes) {
  Result<std::string> head = ReadFileHead(path, kMaxHeaderBytes);
  if (!head.ok()) return head.error();
  return ext == ".pcd" ? CheckPcd(path, *head, file_bytes) : CheckPly(path, *head, file_bytes);
}

}  // namespace hpose
