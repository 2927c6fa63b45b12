#include "core/io/pcd_reader.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <vector>

#include "core/io/atomic_file.h"
#include "core/io/cloud_header_check.h"
#include "core/io/cloud_text.h"
#include "core/io/input_file.h"
#include "core/io/lzf.h"

namespace hpose {
namespace {

struct PcdField {
  std::string name;
  int size = 0;     // bytes per value: 1, 2, 4 or 8.
  char type = 'F';  // I (signed), U (unsigned), F (float).
  int count = 1;    // values per point.
};

struct PcdHeader {
  std::vector<PcdField> fields;
  std::uint64_t width = 0;
  std::uint64_t height = 1;
  std::uint64_t points = 0;
  std::string data;             // ascii, binary or binary_compressed.
  std::size_t data_offset = 0;  // first byte after the DATA line.
  std::size_t point_step = 0;   // bytes per point record.
  int xyz[3] = {-1, -1, -1};    // indices of the x, y and z fields.
};

Result<std::uint64_t> HeaderCount(const std::vector<std::string>& t, const std::string& path) {
  std::uint64_t value = 0;
  if (t.size() != 2 || !ParseUnsigned(t[1], &value)) {
    return FileDataLoss(path, "PCD " + t[0] + " is not a non-negative integer");
  }
  return value;
}

Result<PcdHeader> ParsePcdHeader(const std::string& file, const std::string& path) {
  PcdHeader h;
  std::vector<std::string> sizes, types, counts;
  bool have_width = false, have_points = false;
  std::size_t at = 0;
  while (at < file.size() && h.data.empty()) {
    std::size_t end = file.find('\n', at);
    if (end == std::string::npos) end = file.size();
    const std::vector<std::string> t = SplitWords(file, at, end);
    at = end + 1;
    if (t.empty() || t[0][0] == '#') continue;
    const std::string& key = t[0];
    const std::vector<std::string> values(t.begin() + 1, t.end());
    if (key == "FIELDS" || key == "COLUMNS") {
      for (const std::string& name : values) h.fields.push_back(PcdField{name});
    } else if (key == "SIZE") {
      sizes = values;
    } else if (key == "TYPE") {
      types = values;
    } else if (key == "COUNT") {
      counts = values;
    } else if (key == "WIDTH" || key == "HEIGHT" || key == "POINTS") {
      Result<std::uint64_t> n = HeaderCount(t, path);
      if (!n.ok()) return n.error();
      (key == "WIDTH" ? h.width : key == "HEIGHT" ? h.height : h.points) = *n;
      have_width = have_width || key == "WIDTH";
      have_points = have_points || key == "POINTS";
    } else if (key == "DATA") {
      h.data = values.empty() ? "?" : values[0];
      h.data_offset = std::min(at, file.size());
    }
  }
  if (h.data.empty())
    return FileDataLoss(path, "not a valid PCD file (the header has no DATA line)");
  if (h.fields.empty()) return FileDataLoss(path, "not a valid PCD file (no FIELDS)");
  if (sizes.size() != h.fields.size() || types.size() != h.fields.size() ||
      (!counts.empty() && counts.size() != h.fields.size())) {
    return FileDataLoss(path, "PCD FIELDS, SIZE, TYPE and COUNT differ in length");
  }
  for (std::size_t i = 0; i < h.fields.size(); ++i) {
    PcdField& f = h.fields[i];
    std::uint64_t size = 0, count = 1;
    if (!ParseUnsigned(sizes[i], &size) || (size != 1 && size != 2 && size != 4 && size != 8)) {
      return FileDataLoss(path, "PCD SIZE of field '" + f.name + "' is not 1, 2, 4 or 8");
    }
    if (types[i].size() != 1 || std::string("IUF").find(types[i][0]) == std::string::npos) {
      return FileDataLoss(path, "PCD TYPE of field '" + f.name + "' is not I, U or F");
    }
    if (!counts.empty() && (!ParseUnsigned(counts[i], &count) || count < 1 || count > 1 << 20)) {
      return FileDataLoss(path, "PCD COUNT of field '" + f.name + "' is not a positive integer");
    }
    f.size = static_cast<int>(size);
    f.type = types[i][0];
    f.count = static_cast<int>(count);
    h.point_step += static_cast<std::size_t>(f.size) * f.count;
    for (int c = 0; c < 3; ++c) {
      if (f.name == std::string(1, static_cast<char>('x' + c)) && h.xyz[c] < 0) {
        h.xyz[c] = static_cast<int>(i);
      }
    }
  }
  for (int c = 0; c < 3; ++c) {
    if (h.xyz[c] < 0) {
      return MakeError(ErrorCode::kInvalidArgument, path + ": the PCD has no x, y and z fields");
    }
    const PcdField& f = h.fields[h.xyz[c]];
    if (f.type != 'F' || (f.size != 4 && f.size != 8)) {
      return MakeError(ErrorCode::kInvalidArgument,
                       path + ": field '" + f.name + "' is not a 32- or 64-bit float");
    }
  }
  for (const std::uint64_t n : {h.width, h.height, h.points}) {
    if (n > kMaxCloudFilePoints) {
      return MakeError(ErrorCode::kOutOfRange, path + ": the PCD announces " + std::to_string(n) +
                                                   " points, more than the " +
                                                   std::to_string(kMaxCloudFilePoints) +
                                                   " read at most");
    }
  }
  if (!have_points) h.points = h.width * h.height;
  if (!have_width) {
    h.width = h.points;
    h.height = 1;
  }
  if (h.width * h.height != h.points) {
    return FileDataLoss(path, "PCD WIDTH x HEIGHT (" + std::to_string(h.width) + " x " +
                                  std::to_string(h.height) + ") is not POINTS (" +
                                  std::to_string(h.points) + ")");
  }
  return h;
}

float Coordinate(const std::uint8_t* value, int size) {
  if (size == 8) {
    double d;
    std::memcpy(&d, value, sizeof(d));
    return static_cast<float>(d);
  }
  float f;
  std::memcpy(&f, value, sizeof(f));
  return f;
}

// Binary data: one record of point_step bytes per point. Compressed data, once unpacked: one
// block per field holding that field of every point.
void ReadRecords(const PcdHeader& h, const std::uint8_t* data, bool field_blocks,
                 PointCloud* cloud) {
  std::size_t starts[3] = {}, strides[3] = {};
  std::size_t offset = 0;
  for (std::size_t i = 0; i < h.fields.size(); ++i) {
    const std::size_t bytes = static_cast<std::size_t>(h.fields[i].size) * h.fields[i].count;
    for (int c = 0; c < 3; ++c) {
      if (h.xyz[c] == static_cast<int>(i)) {
        starts[c] = offset;
        strides[c] = field_blocks ? bytes : h.point_step;
      }
    }
    offset += field_blocks ? bytes * h.points : bytes;
  }
  for (std::size_t p = 0; p < h.points; ++p) {
    Eigen::Vector3f& point = cloud->points[p];
    for (int c = 0; c < 3; ++c) {
      point[c] = Coordinate(data + starts[c] + p * strides[c], h.fields[h.xyz[c]].size);
    }
  }
}

Status ReadAscii(const PcdHeader& h, const std::string& file, const std::string& path,
                 PointCloud* cloud) {
  std::size_t token_of[3] = {};
  std::size_t tokens = 0;
  for (std::size_t i = 0; i < h.fields.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      if (h.xyz[c] == static_cast<int>(i)) token_of[c] = tokens;
    }
    tokens += static_cast<std::size_t>(h.fields[i].count);
  }
  std::size_t at = h.data_offset;
  for (std::size_t p = 0; p < h.points; ++p) {
    std::vector<std::string> t;
    while (t.empty() && at < file.size()) {
      std::size_t end = file.find('\n', at);
      if (end == std::string::npos) end = file.size();
      t = SplitWords(file, at, end);
      at = end + 1;
    }
    if (t.size() != tokens) {
      return FileDataLoss(path, t.empty() ? "the PCD ends after " + std::to_string(p) + " of " +
                                                std::to_string(h.points) + " points"
                                          : "PCD point " + std::to_string(p) + " has " +
                                                std::to_string(t.size()) + " values, not " +
                                                std::to_string(tokens));
    }
    for (int c = 0; c < 3; ++c) {
      if (!ParseFloat(t[token_of[c]], &cloud->points[p][c])) {
        return FileDataLoss(
            path, "PCD point " + std::to_string(p) + ": '" + t[token_of[c]] + "' is not a number");
      }
    }
  }
  return Status::Ok();
}

}  // namespace

Result<PointCloud> ReadPcd(const std::string& path) {
  Result<std::string> file = ReadFile(path);
  if (!file.ok()) return file.error();
  Result<PcdHeader> header = ParsePcdHeader(*file, path);
  if (!header.ok()) return header.error();
  const PcdHeader& h = *header;
  const std::size_t remaining = file->size() - h.data_offset;
  const auto* data = reinterpret_cast<const std::uint8_t*>(file->data()) + h.data_offset;
  const std::uint64_t bytes = h.points * h.point_step;

  PointCloud cloud;
  if (h.data == "ascii") {
    if (h.points > remaining) return FileDataLoss(path, "corrupt or truncated PCD point data");
    cloud.points.resize(h.points);
    if (Status s = ReadAscii(h, *file, path, &cloud); !s.ok()) return s.error();
  } else if (h.data == "binary") {
    if (bytes > remaining) {
      return FileDataLoss(path, "corrupt or truncated PCD point data: " + std::to_string(h.points) +
                                    " points need " + std::to_string(bytes) + " bytes, " +
                                    std::to_string(remaining) + " follow the header");
    }
    cloud.points.resize(h.points);
    ReadRecords(h, data, /*field_blocks=*/false, &cloud);
  } else if (h.data == "binary_compressed") {
    if (remaining < 8) return FileDataLoss(path, "truncated binary_compressed sizes");
    std::uint32_t sizes[2];
    std::memcpy(sizes, data, sizeof(sizes));
    if (sizes[0] > remaining - 8 || sizes[1] != bytes) {
      return FileDataLoss(path, "binary_compressed sizes (" + std::to_string(sizes[0]) +
                                    " packed, " + std::to_string(sizes[1]) +
                                    " unpacked) do not fit the file and " +
                                    std::to_string(h.points) + " points");
    }
    std::vector<std::uint8_t> unpacked(bytes);
    if (bytes > 0 && !LzfDecompress(data + 8, sizes[0], unpacked.data(), unpacked.size())) {
      return FileDataLoss(path, "corrupt binary_compressed data (LZF)");
    }
    cloud.points.resize(h.points);
    ReadRecords(h, unpacked.data(), /*field_blocks=*/true, &cloud);
  } else {
    return FileDataLoss(path, "unknown PCD DATA kind '" + h.data + "'");
  }
  if (h.width > 1 && h.height > 1) {
    cloud.width = static_cast<int>(h.width);
    cloud.height = static_cast<int>(h.height);
  }
  return cloud;
}

}  // namespace hpose
