#ifndef HPOSE_SERVER_OPENNI2_SOURCE_H_
#define HPOSE_SERVER_OPENNI2_SOURCE_H_

#include <chrono>
#include <memory>
#include <string>

#include "server/frame_source.h"

namespace hpose::server {

struct Openni2SourceOptions {
  LiveDeviceOptions device;  // for live devices.
  ReplayOptions replay;      // for .oni recordings (fps is ignored: recordings carry timestamps).
};

// Depth frames through OpenNI2: a live device ("openni2://" = any device, "openni2://URI" one
// device) or an .oni recording played back by OpenNI2's file driver. Intrinsics come from the
// stream's field of view (OpenNI2 has no principal point: the image centre is assumed) unless
// options.replay carries the camera's own intrinsics (then used as given).
// Depth in 100 um units is converted to millimetres. OpenNI2 is initialised on Open() and shut
// down on Close() (OpenNI2 counts the calls, so several sources may coexist); a live device's
// source also holds one initialisation from its first Open() to its destruction (see
// LiveDeviceOptions::driver_reload_interval_s).
class Openni2Source final : public FrameSource {
 public:
  // `spec` is "openni2://", "openni2://URI" or a path to an .oni file.
  Openni2Source(std::string spec, Openni2SourceOptions options);
  ~Openni2Source() override;

  // kUnavailable when OpenNI2 cannot start or no (such) device is attached, kNotFound for a
  // missing .oni file, kDataLoss when OpenNI2 cannot read the recording.
  Status Open() override;
  Result<Frame> Next() override;
  void Close() override;

  std::string kind() const override;
  std::string description() const override { return spec_; }
  bool live() const override;
  long frame_count() const override;

 private:
  class Impl;  // holds the OpenNI2 objects (kept out of this header).
  std::string spec_;
  Openni2SourceOptions options_;
  std::unique_ptr<Impl> impl_;
  bool holds_openni_ = false;  // one OpenNI2 initialisation held between Open()s (live device).
  std::chrono::steady_clock::time_point drivers_loaded_;  // when that one was made.
  std::uint64_t sequence_ = 0;
  std::uint64_t epoch_ = 0;  // see Frame::epoch.
  bool opened_before_ = false;
  bool has_last_time_ = false;
  double last_time_s_ = 0.0;
};

// True when `spec` names an OpenNI2 device ("openni2://...").
bool IsOpenni2DeviceSpec(const std::string& spec);

}  // namespace hpose::server

#endif  // HPOSE_SERVER_OPENNI2_SOURCE_H_
