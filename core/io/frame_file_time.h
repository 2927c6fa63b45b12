#ifndef HPOSE_CORE_IO_FRAME_FILE_TIME_H_
#define HPOSE_CORE_IO_FRAME_FILE_TIME_H_

#include <optional>
#include <string>

namespace hpose {

// The time a frame file's name records, in seconds, or nothing when it records none. Two
// conventions are recognised (the directory part of `path` is ignored):
//   a date and time YYYYMMDDTHHMMSS with optional fraction, e.g. PCL's grabbers'
//   "frame_20121214T142255.814212.pcd", read as UTC -> seconds since 1970-01-01 UTC;
//   a name starting with seconds.fraction, e.g. "1355495775.814212.png" or
//   "0001.250_depth.tiff" (TUM RGB-D style) -> those seconds.
// Plain frame counters ("depth_000.png") record no time.
std::optional<double> TimeFromFrameFileName(const std::string& path);

}  // namespace hpose

#endif  // HPOSE_CORE_IO_FRAME_FILE_TIME_H_
