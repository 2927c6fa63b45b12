#ifndef HPOSE_CORE_IO_CLOUD_IO_H_
#define HPOSE_CORE_IO_CLOUD_IO_H_

#include <string>

#include "core/common/status.h"
#include "core/depth/point_cloud.h"

namespace hpose {

// Reads a .pcd (ASCII, binary or binary_compressed; any point type with x, y, z) or .ply cloud
// in metres. Organised PCDs stay organised (NaNs kept). Fails with kNotFound, kDataLoss
// (corrupt or truncated), or kInvalidArgument (no x/y/z fields, unknown extension).
Result<PointCloud> ReadCloud(const std::string& path);

// Whether ReadCloud reads `path` by its extension (.pcd or .ply, any case).
bool IsCloudFile(const std::string& path);

// Writes a binary PCD (XYZ) atomically, organised when the cloud is.
Status WritePcd(const PointCloud& cloud, const std::string& path);

}  // namespace hpose

#endif  // HPOSE_CORE_IO_CLOUD_IO_H_
