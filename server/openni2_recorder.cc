#include "server/openni2_recorder.h"

#include <OpenNI.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>

#include "core/common/clock_limits.h"
#include "core/common/file_names.h"
#include "core/io/atomic_file.h"
#include "core/io/depth_png.h"
#include "core/io/intrinsics_json.h"
#include "server/openni2_devices.h"
#include "server/openni2_file_player.h"
#include "server/openni2_open_check.h"
#include "server/openni2_sensors.h"
#include "server/openni2_source.h"

namespace hpose::server {

namespace {

using Clock = std::chrono::steady_clock;

// A device's failure after some frames were recorded, saying where they are.
Error WithFramesKept(const Error& failure, long frames, const std::string& output) {
  return MakeError(failure.code, failure.message + "; the " + std::to_string(frames) +
                                     " frame(s) recorded before are in " + output);
}

bool Done(const RecordOptions& o, long frames, Clock::time_point start) {
  if (o.frames > 0 && frames >= o.frames) return true;
  return o.duration_s > 0.0 &&
         std::chrono::duration<double>(Clock::now() - start).count() >= o.duration_s;
}

// .oni through openni::Recorder to `output`: the frames are read while the recorder, attached
// to the same stream, writes them. A device that stops sending after some frames leaves them
// in a finished file, the summary returned and *stalled set to why.
Result<RecordSummary> RecordOniTo(const std::string& spec, const std::string& output,
                                  const std::string& shown_as, const RecordOptions& options,
                                  const std::function<bool(long)>& progress, Status* stalled) {
  const std::string uri = spec.substr(std::string("openni2://").size());
  // A recording given as the device (openni2://FILE.oni) is tried in a child first, as a
  // replayed one is: a damaged file can crash OpenNI2's file driver as it opens.
  const Status opens = CheckDeviceUriOpens(uri);
  if (!opens.ok()) return opens.error();
  if (openni::OpenNI::initialize() != openni::STATUS_OK) {
    return MakeError(ErrorCode::kUnavailable, WithOpenni2Error("OpenNI2 failed to initialise"));
  }
  struct Shutdown {
    ~Shutdown() { openni::OpenNI::shutdown(); }
  } shutdown;
  openni::Device device;
  if (device.open(uri.empty() ? openni::ANY_DEVICE : uri.c_str()) != openni::STATUS_OK) {
    return MakeError(ErrorCode::kUnavailable, WithOpenni2Error(DeviceNotFound(uri)));
  }
  openni::VideoStream depth;
  RecordSummary summary;
  summary.format = "oni";
  // A recording as the device (openni2://FILE.oni) that fails before its first frame: its
  // player is let start before the stream and device close (see LetTheFilePlayerStart).
  struct PlayerStarted {
    openni::Device& device;
    openni::VideoStream& stream;
    const long& frames_read;
    ~PlayerStarted() {
      if (frames_read == 0) LetTheFilePlayerStart(device, &stream);
    }
  } player_started{device, depth, summary.frames};
  if (!device.hasSensor(openni::SENSOR_DEPTH)) {
    return MakeError(ErrorCode::kUnavailable, NoDepthStreamError(device, spec));
  }
  if (depth.create(device, openni::SENSOR_DEPTH) != openni::STATUS_OK) {
    return MakeError(ErrorCode::kUnavailable, spec + ": cannot create the depth stream");
  }
  KeepDepthUnregistered(device);  // depth as hposed would stream it.
  SelectPreferredDepthMode(depth);
  // The recorder runs before the stream does, so every frame read below is in the file.
  openni::Recorder recorder;
  if (recorder.create(output.c_str()) != openni::STATUS_OK ||
      recorder.attach(depth) != openni::STATUS_OK || recorder.start() != openni::STATUS_OK) {
    return MakeError(ErrorCode::kInternal,
                     WithOpenni2Error(shown_as + ": OpenNI2 cannot record here"));
  }
  if (depth.start() != openni::STATUS_OK) {
    recorder.destroy();
    return MakeError(ErrorCode::kUnavailable, spec + ": cannot start the depth stream");
  }
  const Clock::time_point start = Clock::now();
  const int timeout_ms = static_cast<int>(options.frame_timeout_s * 1000.0);
  Status failure;
  while (!Done(options, summary.frames, start)) {
    openni::VideoStream* streams[] = {&depth};
    int ready = -1;
    if (openni::OpenNI::waitForAnyStream(streams, 1, &ready, timeout_ms) != openni::STATUS_OK) {
      failure = MakeError(ErrorCode::kUnavailable,
                          spec + ": no frame for " + std::to_string(timeout_ms) + " ms");
      break;
    }
    openni::VideoFrameRef frame;
    if (depth.readFrame(&frame) != openni::STATUS_OK) continue;
    ++summary.frames;
    if (progress && !progress(summary.frames)) break;
  }
  // The stream stops first (no frame arrives after), then the recorder finalises the file (seek
  // table, header).
  depth.stop();
  recorder.stop();
  recorder.destroy();
  depth.destroy();
  device.close();
  summary.duration_s = std::chrono::duration<double>(Clock::now() - start).count();
  if (!failure.ok() && summary.frames == 0) return failure.error();
  *stalled = failure;
  // The recorder takes every frame the device delivers while it runs, read or not: one that
  // arrived after the last read, or while a read was late, is in the file too. The summary
  // counts what the file holds.
  Openni2Source written(output, Openni2SourceOptions{});
  const Status opened = written.Open();
  if (!opened.ok()) {
    return MakeError(ErrorCode::kInternal,
                     shown_as + ": the recording cannot be read back: " + opened.error().message);
  }
  summary.frames = written.frame_count();
  written.Close();
  return summary;
}

// Records through a temporary file beside `output`, renamed over it once finished: a recording
// that fails before its first frame leaves any previous file as it was, and none is ever seen
// half-written. Frames recorded before a device stopped sending are kept, and the error says so.
Result<RecordSummary> RecordOni(const std::string& spec, const std::string& output,
                                const RecordOptions& options,
                                const std::function<bool(long)>& progress) {
  RecordSummary summary;
  Status stalled;
  RemoveStaleTemporaries(output);  // a recording of `output` killed before it finished.
  const Status written = WriteAtomically(output, [&](const std::string& temp) -> Status {
    Result<RecordSummary> recorded = RecordOniTo(spec, temp, output, options, progress, &stalled);
    if (!recorded.ok()) return recorded.error();
    summary = *recorded;
    return Status::Ok();
  });
  if (!written.ok()) return written.error();
  if (!stalled.ok()) {
    return WithFramesKept(stalled.error(), summary.frames, output);
  }
  return summary;
}

// A directory that already holds a recording is refused: the new frames would replace as many
// of the old ones and leave the rest, one recording's frames among another's.
Status CheckNoRecordingIn(const std::string& dir) {
  std::error_code ec;
  for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name == "intrinsics.json" || (name.rfind("frame_", 0) == 0 && EndsWith(name, ".png"))) {
      return MakeError(ErrorCode::kInvalidArgument,
                       dir + " already holds a recording (" + name +
                           "); record to a new directory, or remove that one first");
    }
  }
  return Status::Ok();  // empty, or not there yet.
}

Result<RecordSummary> RecordPngDirectory(const std::string& spec, const std::string& output,
                                         const RecordOptions& options,
                                         const std::function<bool(long)>& progress) {
  const Status fresh = CheckNoRecordingIn(output);
  if (!fresh.ok()) return fresh.error();
  // The device first: one that cannot be opened, or that sends no frame, leaves no directory
  // behind (only one this call made, and only while it is still empty).
  Openni2SourceOptions source_options;
  source_options.device.frame_timeout_s = options.frame_timeout_s;
  Openni2Source source(spec, source_options);
  Status opened = source.Open();
  if (!opened.ok()) return opened.error();
  std::error_code ec;
  const bool made_here = !std::filesystem::exists(output, ec);
  std::filesystem::create_directories(output, ec);
  if (ec) {
    return MakeError(ErrorCode::kInternal, output + ": cannot create directory: " + ec.message());
  }
  struct RemoveIfUnused {
    const std::string& dir;
    bool armed;
    ~RemoveIfUnused() {
      std::error_code ignored;
      if (armed) std::filesystem::remove(dir, ignored);  // removes an empty directory only.
    }
  } remove_if_unused{output, made_here};
  RecordSummary summary;
  summary.format = "png-dir";
  const Clock::time_point start = Clock::now();
  bool wrote_intrinsics = false;
  while (!Done(options, summary.frames, start)) {
    Result<Frame> frame = source.Next();
    if (!frame.ok() && summary.frames > 0) {
      return WithFramesKept(frame.error(), summary.frames, output);
    }
    if (!frame.ok()) return frame.error();
    remove_if_unused.armed = false;
    if (!wrote_intrinsics) {
      Status s = WriteIntrinsicsJson(frame->intrinsics, output + "/intrinsics.json");
      if (!s.ok()) return s.error();
      wrote_intrinsics = true;
    }
    char name[32];
    std::snprintf(name, sizeof(name), "/frame_%06ld.png", summary.frames);
    Status s = WriteDepthPng(frame->depth, output + name);
    if (!s.ok()) return s.error();
    ++summary.frames;
    if (progress && !progress(summary.frames)) break;
  }
  source.Close();
  summary.duration_s = std::chrono::duration<double>(Clock::now() - start).count();
  return summary;
}

}  // namespace

Result<RecordSummary> RecordOpenni2(const std::string& device_spec, const std::string& output,
                                    const RecordOptions& options,
                                    const std::function<bool(long)>& progress) {
  if (!IsOpenni2DeviceSpec(device_spec)) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "'" + device_spec +
                         "' is not an OpenNI2 device (expected openni2:// or "
                         "openni2://URI)");
  }
  if (output.empty()) return MakeError(ErrorCode::kInvalidArgument, "no output path");
  // The frame wait becomes OpenNI2's integer milliseconds: at most a day, as hposed's.
  if (!WaitInRange(options.frame_timeout_s)) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "the frame timeout must be in (0, 86400] seconds, got " +
                         std::to_string(options.frame_timeout_s));
  }
  if (EndsWith(output, ".oni")) return RecordOni(device_spec, output, options, progress);
  return RecordPngDirectory(device_spec, output, options, progress);
}

}  // namespace hpose::server
