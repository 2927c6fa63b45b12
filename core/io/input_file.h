#ifndef HPOSE_CORE_IO_INPUT_FILE_H_
#define HPOSE_CORE_IO_INPUT_FILE_H_

#include <cstdint>
#include <string>

#include "core/common/status.h"

namespace hpose {

// The largest input file hpose reads (bytes): a few minutes of 640x480 depth as PCD fit.
constexpr std::uint64_t kMaxInputFileBytes = std::uint64_t{2} << 30;

// Checks that `path` names an existing regular file of at most `max_bytes` before anything
// reads it: FIFOs, sockets and devices are refused (reading them can block forever or never
// end), so are directories. Returns the file's size in bytes. Fails with kNotFound (no such
// file), kInvalidArgument (not a regular file) or kOutOfRange (too large), naming the path.
Result<std::uint64_t> CheckInputFile(const std::string& path,
                                     std::uint64_t max_bytes = kMaxInputFileBytes);

// The error for a file whose contents are not what its format says (kDataLoss): "<path>: <what>".
Error FileDataLoss(const std::string& path, const std::string& what);

// Reads at most `max_bytes` from the start of a file that passed CheckInputFile.
Result<std::string> ReadFileHead(const std::string& path, std::size_t max_bytes);

}  // namespace hpose

#endif  // HPOSE_CORE_IO_INPUT_FILE_H_
