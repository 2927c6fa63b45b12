#include "server/openni2_source.h"

#include <OpenNI.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <thread>
#include <utility>

#include "server/openni2_devices.h"
#include "server/openni2_file_player.h"
#include "server/openni2_open_check.h"
#include "server/openni2_sensors.h"

namespace hpose::server {

namespace {

constexpr const char* kDevicePrefix = "openni2://";
// How long a recording's next frame may take to come from OpenNI2's player (it reads ahead of
// the reader, so a healthy file's frame is there at once).
constexpr int kRecordingFrameWaitMs = 5000;

bool IsDepthFormat(openni::PixelFormat f) {
  return f == openni::PIXEL_FORMAT_DEPTH_1_MM || f == openni::PIXEL_FORMAT_DEPTH_100_UM;
}

}  // namespace

bool IsOpenni2DeviceSpec(const std::string& spec) { return spec.rfind(kDevicePrefix, 0) == 0; }

// The OpenNI2 objects of one open source.
class Openni2Source::Impl final : public openni::OpenNI::DeviceDisconnectedListener {
 public:
  ~Impl() override { Close(); }

  Status Open(const std::string& spec, const Openni2SourceOptions& options) {
    is_device_ = IsOpenni2DeviceSpec(spec);
    std::string uri;
    if (is_device_) {
      uri = spec.substr(std::strlen(kDevicePrefix));
      const Status opens = CheckDeviceUriOpens(uri);  // a recording given as the device.
      if (!opens.ok()) return opens;
    } else {
      std::error_code ec;
      if (!std::filesystem::is_regular_file(spec, ec)) {
        return MakeError(ErrorCode::kNotFound, spec + ": no such recording");
      }
      uri = spec;
      // A damaged .oni can crash OpenNI2's file driver as it opens: tried in a child first.
      const Status opens = CheckRecordingOpens(spec);
      if (!opens.ok()) return opens;
    }
    if (openni::OpenNI::initialize() != openni::STATUS_OK) {
      return MakeError(ErrorCode::kUnavailable, WithOpenni2Error("OpenNI2 failed to initialise"));
    }
    initialised_ = true;
    if (device_.open(uri.empty() ? openni::ANY_DEVICE : uri.c_str()) != openni::STATUS_OK) {
      const std::string what =
          is_device_ ? DeviceNotFound(uri) : spec + ": OpenNI2 cannot open the recording";
      Close();
      return MakeError(is_device_ ? ErrorCode::kUnavailable : ErrorCode::kDataLoss,
                       WithOpenni2Error(what));
    }
    uri_ = device_.getDeviceInfo().getUri();
    if (!device_.hasSensor(openni::SENSOR_DEPTH)) {
      const std::string what = NoDepthStreamError(device_, spec);
      Close();
      return MakeError(is_device_ ? ErrorCode::kUnavailable : ErrorCode::kDataLoss, what);
    }
    if (stream_.create(device_, openni::SENSOR_DEPTH) != openni::STATUS_OK) {
      Close();
      return MakeError(is_device_ ? ErrorCode::kUnavailable : ErrorCode::kDataLoss,
                       WithOpenni2Error(spec + ": cannot open the depth stream"));
    }
    if (is_device_) {
      KeepDepthUnregistered(device_);
      SelectPreferredDepthMode(
          stream_, options.replay.has_intrinsics ? options.replay.intrinsics.width : 0,
          options.replay.has_intrinsics ? options.replay.intrinsics.height : 0);
      disconnected_ = false;
      openni::OpenNI::addDeviceDisconnectedListener(this);
      listening_ = true;
    } else if (openni::PlaybackControl* playback = device_.getPlaybackControl()) {
      frame_count_ = playback->getNumberOfFrames(stream_);
      // OpenNI2's file player, once a recording without repeat reaches its end, spins through
      // its stream list without the lock that stream destruction takes, so closing it then can
      // crash in the player's thread. With a known frame count this source ends the recording
      // itself (Next() counts frames) and the player repeats, which parks its thread waiting
      // for the next read instead.
      playback->setRepeatEnabled(options.replay.loop || frame_count_ > 0);
      // The player gives a frame when the one before was read (its manual speed, -1); the
      // recorded pace, when asked for, is kept here (Pace). OpenNI2's own pace (speed 1)
      // replaces a frame not read in time by the next, and at the end of a repeating
      // recording the last by the first.
      playback->setSpeed(-1.0f);
      paced_ = options.replay.realtime;
      const int fps = stream_.getVideoMode().getFps();
      frame_period_s_ = fps > 0 ? 1.0 / fps : 1.0 / 30.0;
      has_paced_ = false;
    }
    // Mirrored streams (a PS1080 configured with Mirror=1, or its recording) are read back
    // into the sensor's own columns, frame by frame; a device is asked to stop mirroring first.
    mirrored_ = stream_.getMirroringEnabled();
    if (mirrored_ && is_device_ && stream_.setMirroringEnabled(false) == openni::STATUS_OK) {
      mirrored_ = stream_.getMirroringEnabled();
    }
    if (!IsDepthFormat(stream_.getVideoMode().getPixelFormat())) {
      Close();
      return MakeError(ErrorCode::kDataLoss, spec + ": the depth stream is not in mm or 100 um");
    }
    // The field of view, read once before the stream starts: OpenNI2's file player sets a
    // recording's stream properties from its own thread as it reads the file (again when it
    // starts over, and without the lock a stream's property reads take), so a read while it
    // plays can copy from a property being replaced; a cut-short .oni crashed that way.
    horizontal_fov_ = stream_.getHorizontalFieldOfView();
    vertical_fov_ = stream_.getVerticalFieldOfView();
    if (stream_.start() != openni::STATUS_OK) {
      Close();
      return MakeError(ErrorCode::kUnavailable,
                       WithOpenni2Error(spec + ": cannot start the depth stream"));
    }
    frames_read_ = 0;
    last_index_ = 0;
    wrapped_ = false;
    stalled_ = false;
    loop_ = options.replay.loop;
    has_intrinsics_ = options.replay.has_intrinsics;
    intrinsics_ = options.replay.intrinsics;
    timeout_ms_ = static_cast<int>(std::lround(options.device.frame_timeout_s * 1000.0));
    return Status::Ok();
  }

  Result<Frame> Next(const std::string& spec) {
    if (!stream_.isValid()) return MakeError(ErrorCode::kUnavailable, spec + ": not open");
    const bool ends_itself = !is_device_ && !loop_ && frame_count_ > 0;
    if (ends_itself && (frames_read_ >= frame_count_ || wrapped_)) {
      return MakeError(ErrorCode::kOutOfRange, spec + ": end of recording");
    }
    if (stalled_) {
      return MakeError(ErrorCode::kOutOfRange,
                       spec + ": end of the readable part of a damaged recording");
    }
    if (disconnected_.load()) {
      return MakeError(ErrorCode::kUnavailable, "OpenNI2 device '" + uri_ + "' disconnected");
    }
    // A recording's player gives its next frame as soon as the one before was read; one that
    // gives none (a damaged file can keep it reading forever) ends the recording here rather
    // than leaving the read below waiting for ever.
    const int wait_ms = is_device_ ? timeout_ms_ : std::max(timeout_ms_, kRecordingFrameWaitMs);
    if (!WaitForFrame(wait_ms)) {
      if (disconnected_.load()) {
        return MakeError(ErrorCode::kUnavailable, "OpenNI2 device '" + uri_ + "' disconnected");
      }
      if (is_device_) {
        return MakeError(ErrorCode::kUnavailable, "OpenNI2 device '" + uri_ + "': no frame for " +
                                                      std::to_string(timeout_ms_) + " ms");
      }
      if (frame_count_ <= 0) return MakeError(ErrorCode::kOutOfRange, spec + ": end of recording");
      stalled_ = true;  // its player will give no more: the next read ends the recording.
      return MakeError(ErrorCode::kDataLoss,
                       spec + ": damaged recording: OpenNI2's player gave no frame for " +
                           std::to_string(wait_ms) + " ms after frame " +
                           std::to_string(frames_read_) + " of the " +
                           std::to_string(frame_count_) + " it counts");
    }
    openni::VideoFrameRef ref;
    if (stream_.readFrame(&ref) != openni::STATUS_OK || !ref.isValid()) {
      return MakeError(is_device_ ? ErrorCode::kUnavailable : ErrorCode::kDataLoss,
                       WithOpenni2Error(spec + ": cannot read a depth frame"));
    }
    ++frames_read_;
    player_running_ = true;
    // Should the player (repeating: see Open) start over before the last frame was read, as
    // it did at its own pace, the first frame would take the last one's place: a frame index
    // that goes back is the recording's end, not its first frame again.
    if (ends_itself) {
      if (ref.getFrameIndex() <= last_index_) {
        wrapped_ = true;
        return MakeError(ErrorCode::kOutOfRange, spec + ": end of recording");
      }
      last_index_ = ref.getFrameIndex();
    }
    if (paced_) Pace(ref.getTimestamp());
    Frame frame;
    frame.received = std::chrono::system_clock::now();
    frame.received_steady = std::chrono::steady_clock::now();
    frame.source_time_s = static_cast<double>(ref.getTimestamp()) * 1e-6;
    frame.origin = is_device_ ? uri_ : spec + "#" + std::to_string(ref.getFrameIndex());
    const int w = ref.getWidth();
    const int h = ref.getHeight();
    const int stride = ref.getStrideInBytes();
    if (w <= 0 || h <= 0 || stride < w * 2 || ref.getDataSize() < stride * h) {
      return MakeError(ErrorCode::kDataLoss, spec + ": malformed depth frame");
    }
    // A cropped frame is a window of the video mode's image; its pixels keep their rays.
    const bool cropped = ref.getCroppingEnabled();
    const int full_w = cropped ? ref.getVideoMode().getResolutionX() : w;
    const int full_h = cropped ? ref.getVideoMode().getResolutionY() : h;
    const int origin_u = cropped ? ref.getCropOriginX() : 0;
    const int origin_v = cropped ? ref.getCropOriginY() : 0;
    if (origin_u < 0 || origin_v < 0 || origin_u + w > full_w || origin_v + h > full_h) {
      return MakeError(ErrorCode::kDataLoss,
                       spec + ": a depth frame cropped to " + std::to_string(w) + "x" +
                           std::to_string(h) + " at (" + std::to_string(origin_u) + ", " +
                           std::to_string(origin_v) + ") lies outside its " +
                           std::to_string(full_w) + "x" + std::to_string(full_h) + " image");
    }
    frame.depth = DepthImage(w, h);
    const bool tenth_mm = ref.getVideoMode().getPixelFormat() == openni::PIXEL_FORMAT_DEPTH_100_UM;
    const auto* base = static_cast<const std::uint8_t*>(ref.getData());
    for (int v = 0; v < h; ++v) {
      const auto* row = reinterpret_cast<const openni::DepthPixel*>(base + v * stride);
      for (int u = 0; u < w; ++u) {
        // A mirrored stream's rows are reversed (after cropping, as the PS1080 driver does):
        // reversed again, each pixel is back in the sensor's own column.
        const openni::DepthPixel d = row[mirrored_ ? w - 1 - u : u];
        frame.depth.at(u, v) = tenth_mm ? static_cast<std::uint16_t>((d + 5) / 10) : d;
      }
    }
    Intrinsics& k = frame.intrinsics;
    if (has_intrinsics_) {  // a calibrated camera: the given intrinsics, principal point included.
      if (intrinsics_.width != full_w || intrinsics_.height != full_h) {
        return MakeError(ErrorCode::kInvalidArgument,
                         spec + ": the given intrinsics are for " +
                             std::to_string(intrinsics_.width) + "x" +
                             std::to_string(intrinsics_.height) + " but the depth stream is " +
                             std::to_string(full_w) + "x" + std::to_string(full_h));
      }
      k = intrinsics_;
    } else {
      // OpenNI2 reports only the field of view: the principal point is taken at the image centre.
      k.fx = full_w / (2.0 * std::tan(horizontal_fov_ / 2.0));
      k.fy = full_h / (2.0 * std::tan(vertical_fov_ / 2.0));
      k.cx = full_w / 2.0;
      k.cy = full_h / 2.0;
    }
    k.width = w;
    k.height = h;
    k.cx -= origin_u;
    k.cy -= origin_v;
    if (has_intrinsics_ && !cropped) return frame;
    Status valid = k.Validate();
    if (!valid.ok()) {
      const std::string what = cropped ? "the depth stream's crop window leaves no usable camera: "
                                       : "unusable field of view from OpenNI2: ";
      return MakeError(ErrorCode::kDataLoss, spec + ": " + what + valid.error().message);
    }
    return frame;
  }

  void Close() {
    if (listening_) {
      openni::OpenNI::removeDeviceDisconnectedListener(this);
      listening_ = false;
    }
    if (!player_running_) LetTheFilePlayerStart(device_, &stream_);
    if (stream_.isValid()) {
      stream_.stop();
      stream_.destroy();
    }
    if (device_.isValid()) device_.close();
    if (initialised_) {
      openni::OpenNI::shutdown();
      initialised_ = false;
    }
  }

  void onDeviceDisconnected(const openni::DeviceInfo* info) override {
    if (info != nullptr && uri_ == info->getUri()) disconnected_ = true;
  }

  // Waits up to `timeout_ms` for a frame; a device's wait ends early when its driver reports
  // it disconnected (OpenNI2's wait would not: no frame comes to end it).
  bool WaitForFrame(int timeout_ms) {
    constexpr int kSliceMs = 50;
    openni::VideoStream* streams[] = {&stream_};
    int ready = -1;
    if (!is_device_) {
      const bool arrived =
          openni::OpenNI::waitForAnyStream(streams, 1, &ready, timeout_ms) == openni::STATUS_OK;
      if (arrived) player_running_ = true;
      return arrived;
    }
    using Clock = std::chrono::steady_clock;
    const Clock::time_point end = Clock::now() + std::chrono::milliseconds(timeout_ms);
    while (!disconnected_.load()) {
      const auto left =
          std::chrono::duration_cast<std::chrono::milliseconds>(end - Clock::now()).count();
      if (left <= 0) return false;
      const int slice = static_cast<int>(std::min<long long>(kSliceMs, left));
      if (openni::OpenNI::waitForAnyStream(streams, 1, &ready, slice) == openni::STATUS_OK) {
        return true;
      }
    }
    return false;
  }

  bool is_device() const { return is_device_; }
  long frame_count() const { return frame_count_; }

 private:
  // Holds a recording's frame back until it is due at the recorded pace: as long after the
  // frame before as their timestamps are apart (a frame period when they do not increase, as
  // where a looping recording starts over; at most kMaxPaceStepS, 2 s, as OpenNI2's player
  // caps a gap). A reader more than a frame behind is not sped up to catch up: the pace starts
  // again from the frame it reads.
  void Pace(std::uint64_t timestamp_us) {
    using Clock = std::chrono::steady_clock;
    constexpr double kMaxPaceStepS = 2.0;
    const Clock::time_point now = Clock::now();
    if (!has_paced_) {
      has_paced_ = true;
      last_due_ = now;
    } else {
      const double apart_s = timestamp_us > last_timestamp_us_
                                 ? static_cast<double>(timestamp_us - last_timestamp_us_) * 1e-6
                                 : frame_period_s_;
      const auto step = std::chrono::duration_cast<Clock::duration>(
          std::chrono::duration<double>(std::min(apart_s, kMaxPaceStepS)));
      const Clock::time_point due = last_due_ + step;
      if (due > now) std::this_thread::sleep_until(due);
      last_due_ = now - due > step ? now : due;
    }
    last_timestamp_us_ = timestamp_us;
  }

  openni::Device device_;
  openni::VideoStream stream_;
  std::string uri_;
  bool initialised_ = false;
  bool listening_ = false;
  bool is_device_ = false;
  bool mirrored_ = false;
  double horizontal_fov_ = 0.0;  // radians, as the stream gave them when it opened.
  double vertical_fov_ = 0.0;
  bool loop_ = false;
  bool has_intrinsics_ = false;  // intrinsics_ given by the user replace the field-of-view ones.
  Intrinsics intrinsics_;
  int timeout_ms_ = 2000;
  long frame_count_ = -1;
  long frames_read_ = 0;
  int last_index_ = 0;           // of the last frame read from a recording that ends.
  bool wrapped_ = false;         // its player started over: the recording has ended.
  bool stalled_ = false;         // its player gave no frame in time: the file is damaged.
  bool player_running_ = false;  // a file's player thread has delivered a frame.
  // A recording read at its recorded pace (Pace): when the last frame was due, its timestamp.
  bool paced_ = false;
  bool has_paced_ = false;
  std::chrono::steady_clock::time_point last_due_;
  std::uint64_t last_timestamp_us_ = 0;
  double frame_period_s_ = 1.0 / 30.0;
  std::atomic<bool> disconnected_{false};
};

Openni2Source::Openni2Source(std::string spec, Openni2SourceOptions options)
    : spec_(std::move(spec)), options_(options) {}

Openni2Source::~Openni2Source() {
  impl_.reset();
  if (holds_openni_) openni::OpenNI::shutdown();
}

Status Openni2Source::Open() {
  impl_.reset();
  if (live()) {
    // With no other initialisation left, the shutdown unloads the drivers and the next
    // initialisation loads them afresh: they enumerate the devices present now.
    const auto now = std::chrono::steady_clock::now();
    if (holds_openni_ && now - drivers_loaded_ >= std::chrono::duration<double>(
                                                      options_.device.driver_reload_interval_s)) {
      openni::OpenNI::shutdown();
      holds_openni_ = false;
    }
    if (!holds_openni_ && openni::OpenNI::initialize() == openni::STATUS_OK) {
      holds_openni_ = true;
      drivers_loaded_ = now;
    }  // else Impl::Open() reports OpenNI2's failure.
  }
  auto impl = std::make_unique<Impl>();
  Status status = impl->Open(spec_, options_);
  if (!status.ok()) return status;
  impl_ = std::move(impl);
  if (opened_before_) ++epoch_;  // a reconnection: the device's clock starts over.
  opened_before_ = true;
  has_last_time_ = false;
  return Status::Ok();
}

Result<Frame> Openni2Source::Next() {
  if (!impl_) return MakeError(ErrorCode::kUnavailable, spec_ + ": not open");
  Result<Frame> frame = impl_->Next(spec_);
  if (!frame.ok()) return frame;
  // A recording played with repeat starts its timestamps over when it wraps around.
  if (has_last_time_ && frame->source_time_s < last_time_s_) ++epoch_;
  has_last_time_ = true;
  last_time_s_ = frame->source_time_s;
  frame->sequence = ++sequence_;
  frame->epoch = epoch_;
  return frame;
}

void Openni2Source::Close() { impl_.reset(); }

std::string Openni2Source::kind() const { return live() ? "openni2-device" : "oni"; }

bool Openni2Source::live() const { return IsOpenni2DeviceSpec(spec_); }

long Openni2Source::frame_count() const { return impl_ ? impl_->frame_count() : -1; }

}  // namespace hpose::server
