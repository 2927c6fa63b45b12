#include "core/io/cloud_io.h"

#include <cstring>
#include <string>

#include "core/common/file_names.h"
#include "core/io/atomic_file.h"
#include "core/io/cloud_header_check.h"
#include "core/io/input_file.h"
#include "core/io/pcd_reader.h"
#include "core/io/ply_reader.h"

namespace hpose {

bool IsCloudFile(const std::string& path) {
  const std::string ext = LowerExtension(path);
  return ext == ".pcd" || ext == ".ply";
}

Result<PointCloud> ReadCloud(const std::string& path) {
  Result<std::uint64_t> size = CheckInputFile(path);  // regular files only: no FIFO waits.
  if (!size.ok()) return size.error();
  const std::string ext = LowerExtension(path);
  if (!IsCloudFile(path)) {
    const std::string what =
        ext.empty() ? "has no file extension" : "unknown cloud file extension '" + ext + "'";
    return MakeError(ErrorCode::kInvalidArgument, path + ": " + what + " (expected .pcd or .ply)");
  }
  if (*size == 0) return MakeError(ErrorCode::kDataLoss, path + ": the file is empty");
  // What the header announces must fit the file before the reader allocates it.
  const Status header = CheckCloudFileHeader(path, ext, *size);
  if (!header.ok()) return header.error();
  return ext == ".pcd" ? ReadPcd(path) : ReadPly(path);
}

Status WritePcd(const PointCloud& cloud, const std::string& path) {
  const bool organised = cloud.organised();
  const size_t width = organised ? static_cast<size_t>(cloud.width) : cloud.points.size();
  const size_t height = organised ? static_cast<size_t>(cloud.height) : 1;
  // PCL's header for x, y, z floats (its PointXYZ), then the points as 12-byte records.
  std::string file =
      "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z\n"
      "SIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH " +
      std::to_string(width) + "\nHEIGHT " + std::to_string(height) +
      "\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + std::to_string(cloud.points.size()) +
      "\nDATA binary\n";
  const size_t header_bytes = file.size();
  file.resize(header_bytes + 12 * cloud.points.size());
  for (size_t i = 0; i < cloud.points.size(); ++i) {
    std::memcpy(&file[header_bytes + 12 * i], cloud.points[i].data(), 12);
  }
  return WriteFileAtomically(path, file);
}

}  // namespace hpose
