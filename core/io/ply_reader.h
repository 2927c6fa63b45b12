#ifndef HPOSE_CORE_IO_PLY_READER_H_
#define HPOSE_CORE_IO_PLY_READER_H_

#include <string>

#include "core/common/status.h"
#include "core/depth/point_cloud.h"

namespace hpose {

// Reads the vertices (x, y, z: float or double properties) of a PLY file without PCL: ascii,
// binary_little_endian or binary_big_endian, other elements and properties (lists included)
// skipped. Organised, like PCL reads it, when the viewport of a `camera` element (as PCL
// writes it) or the header's `obj_info num_cols` / `num_rows` multiply to the vertex count
// (both sides above 1). ReadCloud checks the
// header against the file size first (CheckCloudFileHeader); this reader checks every record
// against the file again. Fails with kDataLoss (corrupt or truncated, naming what) or
// kInvalidArgument (no vertex x, y, z float properties), each message naming the path.
Result<PointCloud> ReadPly(const std::string& path);

}  // namespace hpose

#endif  // HPOSE_CORE_IO_PLY_READER_H_
