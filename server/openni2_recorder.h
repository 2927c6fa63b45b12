#ifndef HPOSE_SERVER_OPENNI2_RECORDER_H_
#define HPOSE_SERVER_OPENNI2_RECORDER_H_

#include <functional>
#include <string>

#include "core/common/status.h"

namespace hpose::server {

struct RecordOptions {
  long frames = 100;             // stop after this many frames; 0 = no limit.
  double duration_s = 0.0;       // stop after this long; 0 = no limit.
  double frame_timeout_s = 5.0;  // fail when the device delivers nothing for this long.
};

struct RecordSummary {
  long frames = 0;  // frames written: for .oni, counted in the finished file.
  double duration_s = 0.0;
  std::string format;  // "oni" or "png-dir".
};

// Records depth from an OpenNI2 device ("openni2://" = any, "openni2://URI") to `output`:
// a path ending in ".oni" is written by OpenNI2's own recorder; anything else is a directory
// (created if needed) of 16-bit PNG frames (frame_000000.png, ... millimetres) plus
// intrinsics.json derived from the stream's field of view. `progress(frames_so_far)` is called
// after each frame; returning false stops early. At least one of frames / duration_s must
// bound the recording unless progress stops it. OpenNI2's recorder keeps every frame the device
// delivers while it runs, so an .oni file holds at least the frames read, and more when frames
// arrive as the recording stops or while a read is late; the summary counts the file's frames.
// The .oni file is written beside `output` and renamed over it once finished (and what a
// recording of `output` killed before it finished left beside it is removed first): a recording
// that fails before its first frame leaves a previous file as it was; one whose device stops
// sending after some frames keeps them and fails saying so (a PNG directory keeps its frames the
// same way). Fails with kUnavailable (no device, timeout), kInvalidArgument (not a device spec, or
// a directory that already holds a recording: frame_*.png, intrinsics.json), kDataLoss (a
// recording given as the device, openni2://FILE.oni, that OpenNI2 cannot open without crashing;
// tried in a child process first) or kInternal (cannot write).
Result<RecordSummary> RecordOpenni2(const std::string& device_spec, const std::string& output,
                                    const RecordOptions& options,
                                    const std::function<bool(long)>& progress);

}  // namespace hpose::server

#endif  // HPOSE_SERVER_OPENNI2_RECORDER_H_
