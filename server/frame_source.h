#ifndef HPOSE_SERVER_FRAME_SOURCE_H_
#define HPOSE_SERVER_FRAME_SOURCE_H_

#include <memory>
#include <string>

#include "core/common/status.h"
#include "core/depth/intrinsics.h"
#include "server/frame.h"

namespace hpose::server {

// How a recording is replayed.
struct ReplayOptions {
  bool realtime = true;  // true: at the recorded rate; false: as fast as possible.
  bool loop = false;     // start over at the end instead of finishing.
  // Rate of frame files whose names record no time (see FileSequenceSource), Hz.
  double fps = 30.0;
  // Intrinsics for every depth frame, overriding what the source knows (a calibrated camera);
  // used when has_intrinsics.
  bool has_intrinsics = false;
  Intrinsics intrinsics;
};

// How a live device (OpenNI2) is watched; recordings ignore these.
struct LiveDeviceOptions {
  // Frames must arrive within this time or Next() fails with kUnavailable (the device is lost).
  double frame_timeout_s = 2.0;
  // Between a lost device's Open() attempts OpenNI2 and its drivers stay loaded, so that drivers
  // that watch the bus (PS1080's) report the device the moment it is back, without being loaded
  // anew at every attempt (each load of OpenNI2's drivers loses about 9 KB inside them). They are
  // still reloaded at an Open() when they were last loaded this long ago or more, for drivers
  // that look for devices only when they load. 0: at every Open().
  double driver_reload_interval_s = 60.0;
};

// A stream of depth frames or clouds: a live device or a recording.
//
// Next() blocks until a frame is available (at the replay rate for recordings). It fails with
//   kOutOfRange   at the end of a recording that does not loop (not an error of the data);
//   kUnavailable  when a live device stopped delivering (unplugged, timed out): the caller may
//                 Close() and Open() again later;
//   kDataLoss / kInvalidArgument for one bad file in a directory (the next call moves on).
// Not thread-safe: one reader.
class FrameSource {
 public:
  virtual ~FrameSource() = default;

  // Opens (or reopens) the source. kNotFound / kUnavailable / kDataLoss name the reason.
  virtual Status Open() = 0;
  virtual Result<Frame> Next() = 0;
  virtual void Close() = 0;

  // Short kind name: "openni2-device", "oni", "png-dir", "tiff-dir", "pclzf-dir", "pcd-dir".
  virtual std::string kind() const = 0;
  // What was configured, e.g. "openni2://" or the recording path.
  virtual std::string description() const = 0;
  // True for a live device (dropping frames is fine; losses are retried with back-off).
  virtual bool live() const = 0;
  // Number of frames in a recording, or -1 when unknown (live devices).
  virtual long frame_count() const { return -1; }
};

// Opens the source named by `spec`:
//   "openni2://"          any OpenNI2 device;  "openni2://URI" that device;
//   "*.oni"               an OpenNI2 recording, played through OpenNI2's file driver;
//   a directory of *.png (with intrinsics.json), *.tif / *.tiff or *_depth.pclzf depth frames,
//   or of *.pcd clouds (sensor frame, metres), ordered by file name;
//   a single file of one of these formats (a one-frame recording).
// Fails with kNotFound (missing path) or kInvalidArgument (a file or directory of none of these
// formats). The source is created but not opened.
Result<std::unique_ptr<FrameSource>> MakeFrameSource(const std::string& spec,
                                                     const ReplayOptions& replay,
                                                     const LiveDeviceOptions& device = {});

}  // namespace hpose::server

#endif  // HPOSE_SERVER_FRAME_SOURCE_H_
