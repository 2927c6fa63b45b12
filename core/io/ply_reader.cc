#include "core/io/ply_reader.h"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <vector>

#include "core/io/atomic_file.h"
#include "core/io/cloud_header_check.h"
#include "core/io/cloud_text.h"
#include "core/io/input_file.h"

namespace hpose {
namespace {

enum class PlyFormat { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

// Scalar types: bytes and kind.
struct PlyType {
  int bytes = 0;  // 0: unknown type name.
  bool is_float = false;
  bool is_signed = false;
};

PlyType TypeNamed(const std::string& name) {
  if (name == "char" || name == "int8") return {1, false, true};
  if (name == "uchar" || name == "uint8") return {1, false, false};
  if (name == "short" || name == "int16") return {2, false, true};
  if (name == "ushort" || name == "uint16") return {2, false, false};
  if (name == "int" || name == "int32") return {4, false, true};
  if (name == "uint" || name == "uint32") return {4, false, false};
  if (name == "float" || name == "float32") return {4, true, true};
  if (name == "double" || name == "float64") return {8, true, true};
  return {};
}

struct PlyProperty {
  std::string name;
  PlyType type;  // of the value, or of a list's items.
  bool list = false;
  PlyType count_type;  // of a list's length.
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  PlyFormat format = PlyFormat::kAscii;
  std::vector<PlyElement> elements;
  std::uint64_t columns = 0;  // obj_info num_cols / num_rows (0: not given).
  std::uint64_t rows = 0;
  std::size_t data_offset = 0;
};

Result<PlyHeader> ParsePlyHeader(const std::string& file, const std::string& path) {
  if (file.compare(0, 3, "ply") != 0 || file.size() < 4 || (file[3] != '\n' && file[3] != '\r')) {
    return FileDataLoss(path, "not a PLY file (it does not start with 'ply')");
  }
  PlyHeader h;
  bool have_format = false, ended = false;
  std::size_t at = 0;
  while (at < file.size() && !ended) {
    std::size_t end = file.find('\n', at);
    if (end == std::string::npos) end = file.size();
    const std::vector<std::string> t = SplitWords(file, at, end);
    at = end + 1;
    if (t.empty()) continue;
    if (t[0] == "format") {
      if (t.size() < 2) return FileDataLoss(path, "PLY format line has no format");
      if (t[1] == "ascii") {
        h.format = PlyFormat::kAscii;
      } else if (t[1] == "binary_little_endian") {
        h.format = PlyFormat::kBinaryLittleEndian;
      } else if (t[1] == "binary_big_endian") {
        h.format = PlyFormat::kBinaryBigEndian;
      } else {
        return FileDataLoss(path, "unknown PLY format '" + t[1] + "'");
      }
      have_format = true;
    } else if (t[0] == "element") {
      std::uint64_t count = 0;
      if (t.size() != 3 || !ParseUnsigned(t[2], &count)) {
        return FileDataLoss(path, "PLY element line has no name and non-negative count");
      }
      if (count > kMaxCloudFilePoints) {
        return MakeError(ErrorCode::kOutOfRange, path + ": PLY element '" + t[1] + "' count " +
                                                     std::to_string(count) + " is more than the " +
                                                     std::to_string(kMaxCloudFilePoints) +
                                                     " read at most");
      }
      h.elements.push_back(PlyElement{t[1], count, {}});
    } else if (t[0] == "property") {
      if (h.elements.empty()) return FileDataLoss(path, "PLY property before any element");
      PlyProperty p;
      p.list = t.size() == 5 && t[1] == "list";
      if (p.list) {
        p.count_type = TypeNamed(t[2]);
        p.type = TypeNamed(t[3]);
        p.name = t[4];
        if (p.count_type.bytes == 0 || p.count_type.is_float) {
          return FileDataLoss(path,
                              "PLY list property '" + p.name + "' has no integer length type");
        }
      } else if (t.size() == 3) {
        p.type = TypeNamed(t[1]);
        p.name = t[2];
      } else {
        return FileDataLoss(path, "PLY property line with " + std::to_string(t.size()) + " words");
      }
      if (p.type.bytes == 0)
        return FileDataLoss(path, "PLY property '" + p.name + "' has an unknown type");
      h.elements.back().properties.push_back(p);
    } else if (t[0] == "obj_info" && t.size() == 3 && (t[1] == "num_cols" || t[1] == "num_rows")) {
      ParseUnsigned(t[2], t[1] == "num_cols" ? &h.columns : &h.rows);
    } else if (t[0] == "end_header") {
      ended = true;
    }
  }
  if (!ended) return FileDataLoss(path, "the PLY header has no end_header");
  if (!have_format) return FileDataLoss(path, "the PLY header has no format line");
  h.data_offset = std::min(at, file.size());
  return h;
}

// Reads values from the data part of the file, in either binary byte order or as ASCII words.
class PlyCursor {
 public:
  PlyCursor(const std::string& file, std::size_t at, PlyFormat format)
      : file_(file), at_(at), format_(format) {}

  // The next value as a double; false at the end of the data or on a malformed value.
  bool Next(const PlyType& type, double* value) {
    if (format_ == PlyFormat::kAscii) {
      while (at_ < file_.size() && std::isspace(static_cast<unsigned char>(file_[at_]))) ++at_;
      const std::size_t start = at_;
      while (at_ < file_.size() && !std::isspace(static_cast<unsigned char>(file_[at_]))) ++at_;
      const std::string word = file_.substr(start, at_ - start);
      if (type.is_float && type.bytes == 4) {  // as PCL reads it: straight to float.
        float f = 0.0f;
        if (!ParseFloat(word, &f)) return false;
        *value = f;
        return true;
      }
      return at_ > start && ParseDouble(word, value);
    }
    if (static_cast<std::size_t>(type.bytes) > file_.size() - at_) return false;
    unsigned char bytes[8];
    std::memcpy(bytes, file_.data() + at_, type.bytes);
    at_ += type.bytes;
    if (format_ == PlyFormat::kBinaryBigEndian) std::reverse(bytes, bytes + type.bytes);
    *value = Decode(bytes, type);
    return true;
  }

 private:
  // Bytes in little-endian order (this machine's: x86-64 and ARM64 Linux).
  static double Decode(const unsigned char* b, const PlyType& type) {
    if (type.is_float) {
      if (type.bytes == 8) {
        double d;
        std::memcpy(&d, b, 8);
        return d;
      }
      float f;
      std::memcpy(&f, b, 4);
      return f;
    }
    std::uint64_t u = 0;
    for (int i = type.bytes - 1; i >= 0; --i) u = u << 8 | b[i];
    if (type.is_signed && type.bytes < 8 && (u >> (8 * type.bytes - 1)) != 0) {
      return static_cast<double>(static_cast<std::int64_t>(u) -
                                 (std::int64_t{1} << (8 * type.bytes)));
    }
    return static_cast<double>(u);
  }

  const std::string& file_;
  std::size_t at_;
  PlyFormat format_;
};

// Reads one record of `element` into `values` (one per property; lists are skipped and give 0).
bool ReadRecord(const PlyElement& element, PlyCursor* cursor, std::vector<double>* values) {
  values->assign(element.properties.size(), 0.0);
  for (std::size_t i = 0; i < element.properties.size(); ++i) {
    const PlyProperty& p = element.properties[i];
    if (!p.list) {
      if (!cursor->Next(p.type, &(*values)[i])) return false;
      continue;
    }
    double length = 0.0, item = 0.0;
    if (!cursor->Next(p.count_type, &length) || length < 0 || length > 1 << 20) return false;
    for (int k = 0; k < static_cast<int>(length); ++k) {
      if (!cursor->Next(p.type, &item)) return false;
    }
  }
  return true;
}

int PropertyIndex(const PlyElement& element, const std::string& name) {
  for (std::size_t i = 0; i < element.properties.size(); ++i) {
    if (element.properties[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

}  // namespace

Result<PointCloud> ReadPly(const std::string& path) {
  Result<std::string> file = ReadFile(path);
  if (!file.ok()) return file.error();
  Result<PlyHeader> header = ParsePlyHeader(*file, path);
  if (!header.ok()) return header.error();
  const PlyHeader& h = *header;
  const auto vertex = std::find_if(h.elements.begin(), h.elements.end(),
                                   [](const PlyElement& e) { return e.name == "vertex"; });
  if (vertex == h.elements.end()) {
    return MakeError(ErrorCode::kInvalidArgument, path + ": the PLY has no vertex element");
  }
  int xyz[3] = {-1, -1, -1};
  for (int c = 0; c < 3; ++c) {
    const std::string name(1, static_cast<char>('x' + c));
    xyz[c] = PropertyIndex(*vertex, name);
    if (xyz[c] < 0) {
      return MakeError(ErrorCode::kInvalidArgument,
                       path + ": the PLY vertices have no '" + name + "' property");
    }
    const PlyProperty& p = vertex->properties[xyz[c]];
    if (p.list || !p.type.is_float) {
      return MakeError(ErrorCode::kInvalidArgument,
                       path + ": vertex property '" + name + "' is not a float or double");
    }
  }
  // Every record takes a byte at least: a count beyond the data is refused before allocating.
  const std::size_t remaining = file->size() - h.data_offset;
  if (vertex->count > remaining) {
    return FileDataLoss(path, "the PLY announces " + std::to_string(vertex->count) +
                                  " vertices but only " + std::to_string(remaining) +
                                  " bytes follow the header");
  }
  PointCloud cloud;
  cloud.points.resize(vertex->count);
  // The organisation as PCL writes it: a camera element's viewport after the vertices, or
  // obj_info lines in the header.
  std::uint64_t columns = h.columns, rows = h.rows;
  PlyCursor cursor(*file, h.data_offset, h.format);
  std::vector<double> values;
  for (const PlyElement& e : h.elements) {
    const bool is_vertex = &e == &*vertex;
    for (std::uint64_t r = 0; r < e.count; ++r) {
      if (!ReadRecord(e, &cursor, &values)) {
        return FileDataLoss(path, "corrupt or truncated PLY element '" + e.name + "' (record " +
                                      std::to_string(r) + " of " + std::to_string(e.count) + ")");
      }
      if (is_vertex) {
        for (int c = 0; c < 3; ++c) cloud.points[r][c] = static_cast<float>(values[xyz[c]]);
      }
    }
    const int viewport[2] = {PropertyIndex(e, "viewportx"), PropertyIndex(e, "viewporty")};
    if (e.name == "camera" && e.count > 0 && viewport[0] >= 0 && viewport[1] >= 0 &&
        values[viewport[0]] >= 0 && values[viewport[1]] >= 0) {
      columns = static_cast<std::uint64_t>(values[viewport[0]]);
      rows = static_cast<std::uint64_t>(values[viewport[1]]);
    }
  }
  if (columns > 1 && rows > 1 && columns * rows == vertex->count) {
    cloud.width = static_cast<int>(columns);
    cloud.height = static_cast<int>(rows);
  }
  return cloud;
}

}  // namespace hpose
