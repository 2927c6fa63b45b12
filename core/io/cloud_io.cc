#include "core/io/cloud_io.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <exception>
#include <limits>
#include <mutex>
#include <string>

#include <pcl/PCLPointCloud2.h>
#include <pcl/console/print.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include "core/io/atomic_file.h"
#include "core/io/cloud_header_check.h"
#include "core/io/input_file.h"

namespace hpose {
namespace {

// PCL prints its own errors to the console; hpose reports them through Result instead. The
// verbosity level is process-global, so PCL I/O calls are serialised while it is lowered.
std::mutex& PclIoMutex() {
  static std::mutex mutex;
  return mutex;
}

class QuietPcl final {
 public:
  QuietPcl() : lock_(PclIoMutex()), previous_(pcl::console::getVerbosityLevel()) {
    pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  }
  ~QuietPcl() { pcl::console::setVerbosityLevel(previous_); }
  QuietPcl(const QuietPcl&) = delete;
  QuietPcl& operator=(const QuietPcl&) = delete;

 private:
  std::lock_guard<std::mutex> lock_;
  pcl::console::VERBOSITY_LEVEL previous_;
};

std::string LowerExtension(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

const pcl::PCLPointField* FindField(const pcl::PCLPointCloud2& blob, const std::string& name) {
  for (const pcl::PCLPointField& field : blob.fields) {
    if (field.name == name) return &field;
  }
  return nullptr;
}

// Reads one coordinate of a point; float32 and float64 fields are supported.
float ReadCoordinate(const std::uint8_t* point, const pcl::PCLPointField& field) {
  if (field.datatype == pcl::PCLPointField::FLOAT64) {
    double value;
    std::memcpy(&value, point + field.offset, sizeof(value));
    return static_cast<float>(value);
  }
  float value;
  std::memcpy(&value, point + field.offset, sizeof(value));
  return value;
}

Result<PointCloud> BlobToCloud(const pcl::PCLPointCloud2& blob, const std::string& path) {
  const pcl::PCLPointField* fields[3] = {FindField(blob, "x"), FindField(blob, "y"),
                                         FindField(blob, "z")};
  const char* names[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    if (fields[i] == nullptr) {
      return MakeError(ErrorCode::kInvalidArgument,
                       path + ": the cloud has no '" + names[i] + "' field");
    }
    const auto type = fields[i]->datatype;
    if (type != pcl::PCLPointField::FLOAT32 && type != pcl::PCLPointField::FLOAT64) {
      return MakeError(ErrorCode::kInvalidArgument,
                       path + ": field '" + names[i] + "' is not a 32- or 64-bit float");
    }
    const size_t size = type == pcl::PCLPointField::FLOAT64 ? 8 : 4;
    if (fields[i]->offset + size > blob.point_step) {
      return MakeError(ErrorCode::kDataLoss,
                       path + ": field '" + names[i] + "' lies outside the point record");
    }
  }
  const size_t width = blob.width;
  const size_t height = blob.height;
  const size_t count = width * height;
  if (height > 0 && (blob.row_step < width * blob.point_step ||
                     blob.data.size() < static_cast<size_t>(blob.row_step) * height)) {
    return MakeError(ErrorCode::kDataLoss, path + ": the point data is shorter than the header (" +
                                               std::to_string(count) + " points) announces");
  }
  PointCloud cloud;
  cloud.points.resize(count);
  for (size_t row = 0; row < height; ++row) {
    const std::uint8_t* base = blob.data.data() + row * blob.row_step;
    for (size_t col = 0; col < width; ++col) {
      const std::uint8_t* point = base + col * blob.point_step;
      cloud.points[row * width + col] =
          Eigen::Vector3f(ReadCoordinate(point, *fields[0]), ReadCoordinate(point, *fields[1]),
                          ReadCoordinate(point, *fields[2]));
    }
  }
  if (height > 1 && width > 1) {
    cloud.width = static_cast<int>(width);
    cloud.height = static_cast<int>(height);
  }
  return cloud;
}

}  // namespace

Result<PointCloud> ReadCloud(const std::string& path) {
  Result<std::uint64_t> size = CheckInputFile(path);  // regular files only: no FIFO waits.
  if (!size.ok()) return size.error();
  const std::string ext = LowerExtension(path);
  if (ext != "pcd" && ext != "ply") {
    return MakeError(ErrorCode::kInvalidArgument,
                     path + ": unknown cloud file extension '" + ext + "' (expected .pcd or .ply)");
  }
  if (*size == 0) return MakeError(ErrorCode::kDataLoss, path + ": the file is empty");
  // What the header announces must fit the file before PCL allocates it.
  const Status header = CheckCloudFileHeader(path, ext, *size);
  if (!header.ok()) return header.error();

  pcl::PCLPointCloud2 blob;
  try {
    QuietPcl quiet;
    if (ext == "pcd") {
      pcl::PCDReader reader;
      pcl::PCLPointCloud2 header;
      Eigen::Vector4f origin;
      Eigen::Quaternionf orientation;
      int version = 0;
      int data_type = 0;
      unsigned int data_idx = 0;
      if (reader.readHeader(path, header, origin, orientation, version, data_type, data_idx) < 0) {
        return MakeError(ErrorCode::kDataLoss, path + ": not a valid PCD file (bad header)");
      }
      if (header.fields.empty()) {
        return MakeError(ErrorCode::kDataLoss, path + ": not a valid PCD file (no FIELDS)");
      }
      if (data_idx == 0) {  // every PCD header ends with a DATA line; PCL tolerates its absence.
        return MakeError(ErrorCode::kDataLoss,
                         path + ": not a valid PCD file (the header has no DATA line)");
      }
      if (FindField(header, "x") == nullptr || FindField(header, "y") == nullptr ||
          FindField(header, "z") == nullptr) {
        return MakeError(ErrorCode::kInvalidArgument, path + ": the PCD has no x, y and z fields");
      }
      if (reader.read(path, blob) < 0) {
        return MakeError(ErrorCode::kDataLoss, path + ": corrupt or truncated PCD point data");
      }
    } else {
      pcl::PLYReader reader;
      if (reader.read(path, blob) < 0 || blob.fields.empty()) {
        return MakeError(ErrorCode::kDataLoss, path + ": corrupt or truncated PLY file");
      }
    }
  } catch (const std::exception& e) {
    return MakeError(ErrorCode::kDataLoss, path + ": cannot parse the cloud: " + e.what());
  } catch (...) {
    return MakeError(ErrorCode::kDataLoss, path + ": cannot parse the cloud");
  }
  return BlobToCloud(blob, path);
}

Status WritePcd(const PointCloud& cloud, const std::string& path) {
  pcl::PointCloud<pcl::PointXYZ> out;
  out.points.resize(cloud.points.size());
  bool dense = true;
  for (size_t i = 0; i < cloud.points.size(); ++i) {
    const Eigen::Vector3f& p = cloud.points[i];
    out.points[i].x = p.x();
    out.points[i].y = p.y();
    out.points[i].z = p.z();
    dense = dense && p.allFinite();
  }
  if (cloud.organised()) {
    out.width = static_cast<std::uint32_t>(cloud.width);
    out.height = static_cast<std::uint32_t>(cloud.height);
  } else {
    out.width = static_cast<std::uint32_t>(cloud.points.size());
    out.height = 1;
  }
  out.is_dense = dense;
  if (out.points.empty()) {
    // PCL refuses to write an empty cloud; its header with no data is a valid PCD.
    return WriteFileAtomically(
        path, pcl::PCDWriter::generateHeader<pcl::PointXYZ>(out, 0) + "DATA binary\n");
  }
  return WriteAtomically(path, [&](const std::string& temp) -> Status {
    try {
      QuietPcl quiet;
      pcl::PCDWriter writer;
      if (writer.writeBinary(temp, out) < 0) {
        return MakeError(ErrorCode::kInternal, path + ": cannot write the PCD file");
      }
    } catch (const std::exception& e) {
      return MakeError(ErrorCode::kInternal, path + ": cannot write the PCD file: " + e.what());
    }
    return Status::Ok();
  });
}

}  // namespace hpose
