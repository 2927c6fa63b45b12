#ifndef HPOSE_CORE_IO_PCD_READER_H_
#define HPOSE_CORE_IO_PCD_READER_H_

#include <string>

#include "core/common/status.h"
#include "core/depth/point_cloud.h"

namespace hpose {

// Reads the x, y, z of a PCD file (PCL's point cloud format, versions 0.5 to 0.7) without PCL:
// DATA ascii, binary or binary_compressed (LZF), any fields beside x, y and z (which must be
// 32- or 64-bit floats), organised when WIDTH and HEIGHT both exceed 1 (NaNs kept). ReadCloud
// checks the header against the file size first (CheckCloudFileHeader); this reader checks
// again every size it uses. Fails with kDataLoss (corrupt or truncated, naming what) or
// kInvalidArgument (no x, y, z float fields), each message naming the path.
Result<PointCloud> ReadPcd(const std::string& path);

}  // namespace hpose

#endif  // HPOSE_CORE_IO_PCD_READER_H_
