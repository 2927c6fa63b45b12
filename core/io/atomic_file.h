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

// A path that exists and is not a regular file (a device such as /dev/null or /dev/full, a
// FIFO) is written in place by `write_temp(path)`, with its failures reported, never replaced.
//
// Checks early, before any work, that `path` can be written: not a directory, in an existing,
// writable directory. Fails with kNotFound (missing directory) or kInvalidArgument naming why.
Status CheckOutputPath(const std::string& path);

// Removes the temporary files of `path` that WriteAtomically left behind in a process no longer
// running (a writer killed mid-write: SIGKILL, power loss), and returns how many. Temporaries of
// running processes, this one's included, are left alone. Meant for large outputs written
// rarely (a recording), not for every write: it reads the whole directory.
int RemoveStaleTemporaries(const std::string& path);

// Convenience: atomically writes `contents` to `path`.
Status WriteFileAtomically(const std::string& path, const std::string& contents);

// Reads a whole (small: at most 64 MiB) regular file. kNotFound when it does not exist,
// kInvalidArgument for a directory, FIFO or device, kOutOfRange when too large, kDataLoss when
// unreadable.
Result<std::string> ReadFile(const std::string& path);

}  // namespace hpose

#endif  // HPOSE_CORE_IO_ATOMIC_FILE_H_
