#include "server/openni2_open_check.h"

#include <OpenNI.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "core/common/self_child.h"

namespace hpose::server {
namespace {

constexpr char kCheckVariable[] = "HPOSE_OPENNI2_OPEN_CHECK";
// The child's exit statuses: it opened the recording and read a frame (or waited for one), or
// OpenNI2 refused it without harm.
constexpr int kOpened = 0;
constexpr int kRefused = 3;

// The child: the recording opened as Openni2Source opens it, its properties read and its first
// frame waited for; no close (its process ends here).
[[noreturn]] void RunCheck(const char* path) {
  if (openni::OpenNI::initialize() != openni::STATUS_OK) _exit(kRefused);
  openni::Device device;
  if (device.open(path) != openni::STATUS_OK) _exit(kRefused);
  openni::VideoStream depth;
  if (!device.hasSensor(openni::SENSOR_DEPTH) ||
      depth.create(device, openni::SENSOR_DEPTH) != openni::STATUS_OK) {
    _exit(kRefused);
  }
  if (openni::PlaybackControl* playback = device.getPlaybackControl()) {
    playback->getNumberOfFrames(depth);
    playback->setRepeatEnabled(true);
    playback->setSpeed(-1.0f);
  }
  depth.getVideoMode();
  depth.getMirroringEnabled();
  depth.getHorizontalFieldOfView();
  depth.getVerticalFieldOfView();
  if (depth.start() != openni::STATUS_OK) _exit(kRefused);
  openni::VideoStream* streams[] = {&depth};
  int ready = -1;
  if (openni::OpenNI::waitForAnyStream(streams, 1, &ready, 2000) == openni::STATUS_OK) {
    openni::VideoFrameRef frame;
    depth.readFrame(&frame);
  }
  _exit(kOpened);
}

// Run at start-up of every program that can open a recording: the child of
// CheckRecordingOpens does its check and ends before main.
const bool kRanAsCheck = [] {
  if (const char* path = RunningAsSelfChild(kCheckVariable)) RunCheck(path);
  return false;
}();

}  // namespace

Status CheckRecordingOpens(const std::string& path, double timeout_s) {
  (void)kRanAsCheck;
  const SelfChildRun run = RunSelfAsChild(kCheckVariable, path, timeout_s);
  if (!run.started) return Status::Ok();  // no child to be had: the caller's own open goes ahead.
  if (run.timed_out) {
    return MakeError(ErrorCode::kDataLoss,
                     path + ": damaged recording: OpenNI2 did not open it within " +
                         std::to_string(static_cast<int>(timeout_s)) + " s");
  }
  if (run.signal == 0 && (run.exit_status == kOpened || run.exit_status == kRefused)) {
    return Status::Ok();
  }
  return MakeError(ErrorCode::kDataLoss, path + ": damaged recording: OpenNI2's file driver " +
                                             DescribeSelfChildEnd(run, timeout_s) +
                                             " opening it (checked in a separate process)");
}

Status CheckDeviceUriOpens(const std::string& uri) {
  std::error_code ec;
  if (uri.empty() || !std::filesystem::is_regular_file(uri, ec)) return Status::Ok();
  return CheckRecordingOpens(uri);
}

}  // namespace hpose::server
