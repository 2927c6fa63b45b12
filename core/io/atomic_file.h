#ifndef HPOSE_CORE_IO_ATOMIC_FILE_H_
#define HPOSE_CORE_IO_ATOMIC_FILE_H_

#include <functional>
#include <string>

#include "core/common/status.h"

namespace hpose {

// Writes `path` through a temporary file in the same directory that is renamed over `path` only
// when `write_temp(temp_path)` succeeded, so readers never see a half-written file and a
// failure leaves any previous file intact. Fails with kInternal naming the path.
Status WriteAtomically(const std::string& path,
                       const std::function<Status(const std::string& temp_path)>& write_temp);

// Convenience: atomically writes `contents` to `path`.
Status WriteFileAtomically(const std::string& path, const std::string& contents);

// Reads a whole file. kNotFound when it does not exist, kInternal when unreadable.
Result<std::string> ReadFile(const std::string& path);

}  // namespace hpose

#endif  // HPOSE_CORE_IO_ATOMIC_FILE_H_
