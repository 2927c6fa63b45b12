#ifndef HPOSE_CORE_IO_CLOUD_HEADER_CHECK_H_
#define HPOSE_CORE_IO_CLOUD_HEADER_CHECK_H_

#include <cstdint>
#include <string>

#include "core/common/status.h"

namespace hpose {

// Most points in a cloud file (an 8192 x 8192 organised cloud).
constexpr std::uint64_t kMaxCloudFilePoints = std::uint64_t{8192} * 8192;

// Checks a PCD or PLY file's header against the file's size before a reader allocates what the
// header announces: point / element counts must be non-negative, at most kMaxCloudFilePoints
// (kOutOfRange beyond), and the data they announce must fit in the bytes after the header
// (binary: count x record size; ASCII: two bytes per value at least; PCD binary_compressed: the
// compressed and uncompressed sizes must agree with the header and the file). Fails with
// kDataLoss naming the field otherwise. `ext` is ".pcd" or ".ply"; `file_bytes` the file's size.
Status CheckCloudFileHeader(const std::string& path, const std::string& ext,
                            std::uint64_t file_bytes);

}  // namespace hpose

#endif  // HPOSE_CORE_IO_CLOUD_HEADER_CHECK_H_
