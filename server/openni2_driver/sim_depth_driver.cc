// libHposeSimDepth: an OpenNI2 device driver that serves simulated depth frames, so the OpenNI2
// capture and recording paths of hpose run through OpenNI2 itself on machines without a Kinect.
//
// The driver exposes one depth-only device, URI "hpose-sim://depth0". Its frames come from
//   HPOSE_SIM_DEPTH_DIR   a directory of 16-bit PNG depth frames (millimetres) and their
//                         intrinsics.json, served in name order and looped; when unset, a
//                         procedural scene (a flat floor seen from 0.34 m, a box 1 m ahead).
// Further settings, all optional:
//   HPOSE_SIM_DEPTH_FPS               frame rate (default 30).
//   HPOSE_SIM_DEPTH_DISCONNECT_AFTER  after this many frames the device disappears (unplugged):
//                                     frames stop, OpenNI2 is told it disconnected, and opening
//                                     it fails until it reappears.
//   HPOSE_SIM_DEPTH_OFFLINE_MS        how long it stays away (default 1500 ms); it then
//                                     reconnects and serves frames again.
//   HPOSE_SIM_DEPTH_UNPLUGGED_FILE    while this file exists the device is unplugged (also across
//                                     reloads of the driver, as a real one stays away): it is not
//                                     listed, opening it fails and its frames stop. Removing the
//                                     file plugs it back.
//   HPOSE_SIM_DEPTH_NO_HOTPLUG=1      the driver tells OpenNI2 of devices only when it loads,
//                                     not when they come and go later (as drivers without a
//                                     watch on the USB bus do): a device plugged back is found
//                                     only by a driver loaded after.
//   HPOSE_SIM_DEPTH_LOAD_LOG          a line is appended to this file each time the driver is
//                                     initialised (tests count OpenNI2's loads of its drivers).
//   HPOSE_SIM_DEPTH_AS_IR=1           the device's one sensor is an infrared camera instead
//                                     (16-bit grey frames of the same data): a device, and its
//                                     recordings, without depth.
//   HPOSE_SIM_DEPTH_WITH_IR=1         the device has an infrared camera beside its depth sensor
//                                     (16-bit grey frames of the same data), as PS1080s have:
//                                     recordings of both streams.
//   HPOSE_SIM_DEPTH_MIRRORED=1        the stream starts mirrored (each row reversed), as a
//                                     PS1080 device with Mirror=1 in its configuration does;
//                                     a client may switch mirroring either way. "fixed": it
//                                     mirrors and refuses to stop (as devices whose mirroring
//                                     is done in firmware may).
//   HPOSE_SIM_DEPTH_100_UM=1          the depth stream's pixel format is 100 um units: the
//                                     frames' values are served as they are, in those units.
//   HPOSE_SIM_DEPTH_MODES=several     the depth sensor lists two modes, both 30 fps in 1 mm: half
//                                     the frames' size (every second pixel of every second
//                                     row), which it starts in as PS1080's starts in 320x240,
//                                     and their full size.
//   HPOSE_SIM_DEPTH_REGISTERED=1      the device starts with depth registered to its (absent)
//                                     colour camera, as PS1080's Registration=1: the frames
//                                     are drawn from that camera's place, here shifted 8
//                                     pixels right; a client may switch registration off.
//   HPOSE_SIM_DEPTH_CROP=X,Y,W,H      the stream starts cropped to that window of the image;
//                                     a client may crop otherwise or switch cropping off.
// Cropping then mirroring, as the PS1080 driver's software paths do: the window is in the
// sensor's (unmirrored) columns and the cropped frame is reversed.
// OpenNI2 reports the field of view only; the driver derives it from the intrinsics (principal
// point assumed at the image centre).
#include <dirent.h>
#include <sys/stat.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <mutex>
#include <new>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

// The driver API's export macro allocates with these (defined by OpenNI's private XnOS headers).
#define XN_NEW(type, arg) new (std::nothrow) type(arg)
#define XN_DELETE(p) delete (p)
#include <Driver/OniDriverAPI.h>

namespace {

constexpr const char* kUri = "hpose-sim://depth0";
constexpr int kRegistrationShift = 8;  // pixels, while depth is registered to colour.

struct FrameSet {
  int width = 320;
  int height = 240;
  double fx = 297.1;
  double fy = 295.5;
  double cx = 160.0;
  double cy = 120.0;
  std::vector<std::vector<std::uint16_t>> frames;  // each width * height, millimetres.
};

int EnvInt(const char* name, int fallback) {
  const char* v = std::getenv(name);
  if (v == nullptr || *v == '\0') return fallback;
  char* end = nullptr;
  const long parsed = std::strtol(v, &end, 10);
  return (end != nullptr && *end == '\0') ? static_cast<int>(parsed) : fallback;
}

std::string EnvString(const char* name) {
  const char* v = std::getenv(name);
  return v != nullptr ? std::string(v) : std::string();
}

bool FileExists(const std::string& path) {
  struct stat st {};
  return stat(path.c_str(), &st) == 0;
}

// A floor 0.34 m below a horizontal sensor, with a 0.3 x 0.2 x 0.58 m box whose front face is
// 1 m ahead; beyond 4 m nothing is seen.
std::vector<std::uint16_t> ProceduralFrame(const FrameSet& set) {
  std::vector<std::uint16_t> mm(static_cast<size_t>(set.width) * set.height, 0);
  const double h = 0.34;
  for (int v = 0; v < set.height; ++v) {
    for (int u = 0; u < set.width; ++u) {
      const double dx = (u - set.cx) / set.fx;  // ray direction with z = 1.
      const double dy = (v - set.cy) / set.fy;
      double z = 0.0;
      // Box front face at z = 1.0, x in [-0.15, 0.15], y (down) in [h - 0.58, h].
      const double bz = 1.0;
      const double bx = dx * bz, by = dy * bz;
      if (bx >= -0.15 && bx <= 0.15 && by >= h - 0.58 && by <= h) {
        z = bz;
      } else if (dy > 1e-6) {
        z = h / dy;  // the floor, y = h.
      }
      if (z > 0.0 && z < 4.0) mm[static_cast<size_t>(v) * set.width + u] = std::uint16_t(z * 1000);
    }
  }
  return mm;
}

bool LoadDirectory(const std::string& dir, FrameSet* set) {
  std::ifstream in(dir + "/intrinsics.json");
  if (!in) return false;
  nlohmann::json j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object()) return false;
  try {
    set->width = j.at("width").get<int>();
    set->height = j.at("height").get<int>();
    set->fx = j.at("fx").get<double>();
    set->fy = j.at("fy").get<double>();
    set->cx = j.at("cx").get<double>();
    set->cy = j.at("cy").get<double>();
  } catch (const nlohmann::json::exception&) {
    return false;
  }
  std::vector<std::string> names;
  if (DIR* d = opendir(dir.c_str())) {
    while (dirent* e = readdir(d)) {
      const std::string name = e->d_name;
      if (name.size() > 4 && name.compare(name.size() - 4, 4, ".png") == 0) names.push_back(name);
    }
    closedir(d);
  }
  std::sort(names.begin(), names.end());
  for (const std::string& name : names) {
    const cv::Mat img = cv::imread(dir + "/" + name, cv::IMREAD_UNCHANGED);
    if (img.empty() || img.type() != CV_16UC1 || img.cols != set->width ||
        img.rows != set->height) {
      continue;
    }
    std::vector<std::uint16_t> mm(static_cast<size_t>(img.cols) * img.rows);
    for (int r = 0; r < img.rows; ++r) {
      std::memcpy(&mm[static_cast<size_t>(r) * img.cols], img.ptr<std::uint16_t>(r),
                  sizeof(std::uint16_t) * img.cols);
    }
    set->frames.push_back(std::move(mm));
  }
  return !set->frames.empty();
}

// Shared between the driver (connect/disconnect) and its stream (frames).
struct DeviceState {
  FrameSet frames;
  OniSensorType sensor = ONI_SENSOR_DEPTH;  // ONI_SENSOR_IR: see HPOSE_SIM_DEPTH_AS_IR.
  OniPixelFormat format = ONI_PIXEL_FORMAT_DEPTH_1_MM;
  int fps = 30;
  int disconnect_after = -1;  // frames; -1 = never.
  int offline_ms = 1500;
  std::vector<OniVideoMode> modes;     // the first is the one a stream starts in.
  std::vector<OniVideoMode> ir_modes;  // with HPOSE_SIM_DEPTH_WITH_IR, the second sensor's.
  bool mirrored = false;               // at the stream's creation.
  bool mirroring_fixed = false;
  std::atomic<bool> registered{false};  // depth to colour (ONI_IMAGE_REGISTRATION_...).
  OniCropping cropping{};               // at the stream's creation.
  std::atomic<bool> online{true};
  std::atomic<bool> stale{false};  // without hotplug: unplugged since the driver loaded.
  std::atomic<int> frames_served{0};
};

class SimDepthStream final : public oni::driver::StreamBase {
 public:
  // A stream of `sensor`, whose modes are `modes` (kept by `state`).
  SimDepthStream(DeviceState* state, OniSensorType sensor, const std::vector<OniVideoMode>* modes)
      : state_(state),
        sensor_(sensor),
        modes_(modes),
        mode_(modes->front()),
        mirrored_(state->mirrored),
        cropping_(state->cropping) {}
  ~SimDepthStream() override { stop(); }

  OniStatus start() override {
    std::lock_guard<std::mutex> lock(mu_);
    if (running_) return ONI_STATUS_OK;
    running_ = true;
    thread_ = std::thread([this] { Loop(); });
    return ONI_STATUS_OK;
  }

  void stop() override {
    {
      std::lock_guard<std::mutex> lock(mu_);
      if (!running_) return;
      running_ = false;
    }
    cv_.notify_all();
    if (thread_.joinable()) thread_.join();
  }

  int getRequiredFrameSize() override {
    std::lock_guard<std::mutex> lock(mu_);
    return mode_.resolutionX * mode_.resolutionY * static_cast<int>(sizeof(OniDepthPixel));
  }

  OniBool isPropertySupported(int id) override {
    switch (id) {
      case ONI_STREAM_PROPERTY_VIDEO_MODE:
      case ONI_STREAM_PROPERTY_HORIZONTAL_FOV:
      case ONI_STREAM_PROPERTY_VERTICAL_FOV:
      case ONI_STREAM_PROPERTY_MAX_VALUE:
      case ONI_STREAM_PROPERTY_MIN_VALUE:
      case ONI_STREAM_PROPERTY_STRIDE:
      case ONI_STREAM_PROPERTY_MIRRORING:
      case ONI_STREAM_PROPERTY_CROPPING:
        return TRUE;
      default:
        return FALSE;
    }
  }

  OniStatus getProperty(int id, void* data, int* size) override {
    const FrameSet& f = state_->frames;
    switch (id) {
      case ONI_STREAM_PROPERTY_VIDEO_MODE: {
        std::lock_guard<std::mutex> lock(mu_);
        return Put(mode_, data, size);
      }
      case ONI_STREAM_PROPERTY_HORIZONTAL_FOV:
        return Put(static_cast<float>(2.0 * std::atan(f.width / (2.0 * f.fx))), data, size);
      case ONI_STREAM_PROPERTY_VERTICAL_FOV:
        return Put(static_cast<float>(2.0 * std::atan(f.height / (2.0 * f.fy))), data, size);
      case ONI_STREAM_PROPERTY_MAX_VALUE:
        return Put(10000, data, size);
      case ONI_STREAM_PROPERTY_MIN_VALUE:
        return Put(0, data, size);
      case ONI_STREAM_PROPERTY_STRIDE: {
        std::lock_guard<std::mutex> lock(mu_);
        return Put(mode_.resolutionX * static_cast<int>(sizeof(OniDepthPixel)), data, size);
      }
      case ONI_STREAM_PROPERTY_MIRRORING:
        return Put(static_cast<OniBool>(mirrored_.load() ? TRUE : FALSE), data, size);
      case ONI_STREAM_PROPERTY_CROPPING: {
        // OpenNI2's file player drops frames of streams that do not report cropping.
        std::lock_guard<std::mutex> lock(mu_);
        OniCropping c = cropping_;
        if (!c.enabled) c = OniCropping{FALSE, 0, 0, mode_.resolutionX, mode_.resolutionY};
        return Put(c, data, size);
      }
      default:
        return ONI_STATUS_NOT_SUPPORTED;
    }
  }

  OniStatus setProperty(int id, const void* data, int size) override {
    if (id == ONI_STREAM_PROPERTY_VIDEO_MODE && size == static_cast<int>(sizeof(OniVideoMode))) {
      const auto* m = static_cast<const OniVideoMode*>(data);
      for (const OniVideoMode& listed : *modes_) {
        if (m->pixelFormat == listed.pixelFormat && m->resolutionX == listed.resolutionX &&
            m->resolutionY == listed.resolutionY && m->fps == listed.fps) {
          std::lock_guard<std::mutex> lock(mu_);
          if (running_) return ONI_STATUS_OUT_OF_FLOW;
          mode_ = listed;
          return ONI_STATUS_OK;
        }
      }
      return ONI_STATUS_NOT_SUPPORTED;
    }
    if (id == ONI_STREAM_PROPERTY_CROPPING && size == static_cast<int>(sizeof(OniCropping))) {
      const OniCropping c = *static_cast<const OniCropping*>(data);
      std::lock_guard<std::mutex> lock(mu_);
      if (c.enabled && !WithinImage(c)) return ONI_STATUS_BAD_PARAMETER;
      cropping_ = c;
      return ONI_STATUS_OK;
    }
    if (id == ONI_STREAM_PROPERTY_MIRRORING && size == static_cast<int>(sizeof(OniBool))) {
      const bool mirror = *static_cast<const OniBool*>(data) != FALSE;
      if (state_->mirroring_fixed && !mirror) return ONI_STATUS_NOT_SUPPORTED;
      mirrored_ = mirror;
      return ONI_STATUS_OK;
    }
    return ONI_STATUS_NOT_SUPPORTED;
  }

 private:
  template <typename T>
  static OniStatus Put(const T& value, void* data, int* size) {
    if (*size != static_cast<int>(sizeof(T))) return ONI_STATUS_BAD_PARAMETER;
    std::memcpy(data, &value, sizeof(T));
    return ONI_STATUS_OK;
  }

  void Loop() {
    const auto period = std::chrono::microseconds(1000000 / std::max(1, state_->fps));
    auto next = std::chrono::steady_clock::now();
    int index = 0;
    std::unique_lock<std::mutex> lock(mu_);
    while (running_) {
      next += period;
      cv_.wait_until(lock, next, [this] { return !running_; });
      if (!running_) break;
      if (!state_->online.load() || state_->stale.load()) continue;  // unplugged: nothing.
      lock.unlock();
      Emit(index++);
      lock.lock();
    }
  }

  // Whether `c` lies in the current mode's image (mu_ held).
  bool WithinImage(const OniCropping& c) const {
    return c.originX >= 0 && c.originY >= 0 && c.width > 0 && c.height > 0 &&
           c.originX + c.width <= mode_.resolutionX && c.originY + c.height <= mode_.resolutionY;
  }

  void Emit(int index) {
    OniFrame* frame = getServices().acquireFrame();
    if (frame == nullptr) return;
    const FrameSet& f = state_->frames;
    const std::vector<std::uint16_t>& src = f.frames[index % f.frames.size()];
    OniCropping c;
    OniVideoMode mode;
    {
      std::lock_guard<std::mutex> lock(mu_);
      c = cropping_;
      mode = mode_;
    }
    if (!c.enabled) c = OniCropping{FALSE, 0, 0, mode.resolutionX, mode.resolutionY};
    const int step = f.width / mode.resolutionX;  // 2 in a half-size mode.
    const int shift = state_->registered.load() ? kRegistrationShift : 0;
    const bool mirrored = mirrored_.load();
    auto* out = static_cast<std::uint16_t*>(frame->data);
    for (int v = 0; v < c.height; ++v) {
      std::uint16_t* dst = out + static_cast<size_t>(v) * c.width;
      for (int u = 0; u < c.width; ++u) {
        const int column = mirrored ? c.width - 1 - u : u;
        const int from = (c.originX + u) * step - shift;
        dst[column] = from < 0 ? 0
                               : src[static_cast<size_t>(c.originY + v) * step * f.width +
                                     static_cast<size_t>(from)];
      }
    }
    frame->dataSize = c.width * c.height * static_cast<int>(sizeof(std::uint16_t));
    frame->sensorType = sensor_;
    frame->timestamp = static_cast<uint64_t>(index) * 1000000ull / std::max(1, state_->fps);
    frame->frameIndex = index + 1;
    frame->width = c.width;
    frame->height = c.height;
    frame->videoMode = mode;
    frame->croppingEnabled = c.enabled;
    frame->cropOriginX = c.originX;
    frame->cropOriginY = c.originY;
    frame->stride = c.width * static_cast<int>(sizeof(OniDepthPixel));
    raiseNewFrame(frame);
    getServices().releaseFrame(frame);
    state_->frames_served.fetch_add(1);
  }

  DeviceState* state_;
  OniSensorType sensor_;
  const std::vector<OniVideoMode>* modes_;
  OniVideoMode mode_;  // guarded by mu_.
  std::atomic<bool> mirrored_;
  std::mutex mu_;
  OniCropping cropping_;  // guarded by mu_.
  std::condition_variable cv_;
  bool running_ = false;
  std::thread thread_;
};

class SimDepthDevice final : public oni::driver::DeviceBase {
 public:
  explicit SimDepthDevice(DeviceState* state) : state_(state) {
    sensors_[0].sensorType = state->sensor;
    sensors_[0].numSupportedVideoModes = static_cast<int>(state->modes.size());
    sensors_[0].pSupportedVideoModes = state->modes.data();
    if (!state->ir_modes.empty()) {
      sensors_[1].sensorType = ONI_SENSOR_IR;
      sensors_[1].numSupportedVideoModes = static_cast<int>(state->ir_modes.size());
      sensors_[1].pSupportedVideoModes = state->ir_modes.data();
      sensor_count_ = 2;
    }
  }

  OniStatus getSensorInfoList(OniSensorInfo** infos, int* count) override {
    *infos = sensors_;
    *count = sensor_count_;
    return ONI_STATUS_OK;
  }

  oni::driver::StreamBase* createStream(OniSensorType type) override {
    if (type == state_->sensor) {
      return new (std::nothrow) SimDepthStream(state_, type, &state_->modes);
    }
    if (type == ONI_SENSOR_IR && !state_->ir_modes.empty()) {
      return new (std::nothrow) SimDepthStream(state_, type, &state_->ir_modes);
    }
    return nullptr;
  }
  void destroyStream(oni::driver::StreamBase* stream) override { delete stream; }

  OniBool isPropertySupported(int id) override {
    return id == ONI_DEVICE_PROPERTY_SERIAL_NUMBER || id == ONI_DEVICE_PROPERTY_IMAGE_REGISTRATION
               ? TRUE
               : FALSE;
  }
  OniBool isImageRegistrationModeSupported(OniImageRegistrationMode mode) override {
    return mode == ONI_IMAGE_REGISTRATION_OFF || mode == ONI_IMAGE_REGISTRATION_DEPTH_TO_COLOR;
  }
  OniStatus setProperty(int id, const void* data, int size) override {
    if (id != ONI_DEVICE_PROPERTY_IMAGE_REGISTRATION ||
        size != static_cast<int>(sizeof(OniImageRegistrationMode))) {
      return ONI_STATUS_NOT_SUPPORTED;
    }
    const auto mode = *static_cast<const OniImageRegistrationMode*>(data);
    if (!isImageRegistrationModeSupported(mode)) return ONI_STATUS_NOT_SUPPORTED;
    state_->registered = mode == ONI_IMAGE_REGISTRATION_DEPTH_TO_COLOR;
    return ONI_STATUS_OK;
  }
  OniStatus getProperty(int id, void* data, int* size) override {
    if (id == ONI_DEVICE_PROPERTY_IMAGE_REGISTRATION) {
      if (*size != static_cast<int>(sizeof(OniImageRegistrationMode))) {
        return ONI_STATUS_BAD_PARAMETER;
      }
      *static_cast<OniImageRegistrationMode*>(data) = state_->registered.load()
                                                          ? ONI_IMAGE_REGISTRATION_DEPTH_TO_COLOR
                                                          : ONI_IMAGE_REGISTRATION_OFF;
      return ONI_STATUS_OK;
    }
    if (id != ONI_DEVICE_PROPERTY_SERIAL_NUMBER) return ONI_STATUS_NOT_SUPPORTED;
    const char serial[] = "HPOSE-SIM-0";
    if (*size < static_cast<int>(sizeof(serial))) return ONI_STATUS_BAD_PARAMETER;
    std::memcpy(data, serial, sizeof(serial));
    *size = sizeof(serial);
    return ONI_STATUS_OK;
  }

 private:
  DeviceState* state_;
  OniSensorInfo sensors_[2]{};
  int sensor_count_ = 1;
};

class SimDepthDriver final : public oni::driver::DriverBase {
 public:
  explicit SimDepthDriver(OniDriverServices* services) : DriverBase(services) {}

  OniStatus initialize(oni::driver::DeviceConnectedCallback connected,
                       oni::driver::DeviceDisconnectedCallback disconnected,
                       oni::driver::DeviceStateChangedCallback state_changed,
                       void* cookie) override {
    const OniStatus rc = DriverBase::initialize(connected, disconnected, state_changed, cookie);
    if (rc != ONI_STATUS_OK) return rc;
    const char* dir = std::getenv("HPOSE_SIM_DEPTH_DIR");
    if (dir != nullptr && *dir != '\0') {
      if (!LoadDirectory(dir, &state_.frames)) {
        getServices().errorLoggerAppend("hpose-sim: no usable frames in '%s'", dir);
        return ONI_STATUS_ERROR;
      }
    } else {
      state_.frames.frames.push_back(ProceduralFrame(state_.frames));
    }
    state_.fps = std::max(1, EnvInt("HPOSE_SIM_DEPTH_FPS", 30));
    state_.disconnect_after = EnvInt("HPOSE_SIM_DEPTH_DISCONNECT_AFTER", -1);
    state_.offline_ms = std::max(0, EnvInt("HPOSE_SIM_DEPTH_OFFLINE_MS", 1500));
    unplugged_file_ = EnvString("HPOSE_SIM_DEPTH_UNPLUGGED_FILE");
    hotplug_ = EnvInt("HPOSE_SIM_DEPTH_NO_HOTPLUG", 0) == 0;
    if (EnvInt("HPOSE_SIM_DEPTH_AS_IR", 0) != 0) {
      state_.sensor = ONI_SENSOR_IR;
      state_.format = ONI_PIXEL_FORMAT_GRAY16;
    } else if (EnvInt("HPOSE_SIM_DEPTH_100_UM", 0) != 0) {
      state_.format = ONI_PIXEL_FORMAT_DEPTH_100_UM;
    }
    const OniVideoMode full{state_.format, state_.frames.width, state_.frames.height, state_.fps};
    state_.modes.assign(1, full);
    if (EnvString("HPOSE_SIM_DEPTH_MODES") == "several" && state_.sensor == ONI_SENSOR_DEPTH &&
        state_.frames.width % 2 == 0 && state_.frames.height % 2 == 0) {
      OniVideoMode half = full;
      half.resolutionX /= 2;
      half.resolutionY /= 2;
      state_.modes.insert(state_.modes.begin(), half);
    }
    const std::string mirrored = EnvString("HPOSE_SIM_DEPTH_MIRRORED");
    state_.mirroring_fixed = mirrored == "fixed";
    if (EnvInt("HPOSE_SIM_DEPTH_WITH_IR", 0) != 0 && state_.sensor == ONI_SENSOR_DEPTH) {
      state_.ir_modes.assign(1, OniVideoMode{ONI_PIXEL_FORMAT_GRAY16, state_.frames.width,
                                             state_.frames.height, state_.fps});
    }
    state_.registered = EnvInt("HPOSE_SIM_DEPTH_REGISTERED", 0) != 0;
    state_.mirrored = state_.mirroring_fixed || EnvInt("HPOSE_SIM_DEPTH_MIRRORED", 0) != 0;
    const std::string crop = EnvString("HPOSE_SIM_DEPTH_CROP");
    if (!crop.empty()) {
      OniCropping& c = state_.cropping;
      if (std::sscanf(crop.c_str(), "%d,%d,%d,%d", &c.originX, &c.originY, &c.width, &c.height) !=
              4 ||
          c.originX < 0 || c.originY < 0 || c.width <= 0 || c.height <= 0 ||
          c.originX + c.width > state_.frames.width ||
          c.originY + c.height > state_.frames.height) {
        getServices().errorLoggerAppend(
            "hpose-sim: HPOSE_SIM_DEPTH_CROP '%s' is no window of the "
            "image (X,Y,W,H)",
            crop.c_str());
        return ONI_STATUS_ERROR;
      }
      c.enabled = TRUE;
    }
    const std::string load_log = EnvString("HPOSE_SIM_DEPTH_LOAD_LOG");
    if (!load_log.empty()) std::ofstream(load_log, std::ios::app) << "initialised\n";

    std::memset(&info_, 0, sizeof(info_));
    std::snprintf(info_.uri, sizeof(info_.uri), "%s", kUri);
    std::snprintf(info_.vendor, sizeof(info_.vendor), "hpose");
    std::snprintf(info_.name, sizeof(info_.name), "simulated depth camera");
    state_.online = unplugged_file_.empty() || !FileExists(unplugged_file_);
    if (state_.online) deviceConnected(&info_);
    if (state_.disconnect_after >= 0 || !unplugged_file_.empty()) {
      running_ = true;
      watcher_ = std::thread([this] { Watch(); });
    }
    return ONI_STATUS_OK;
  }

  oni::driver::DeviceBase* deviceOpen(const char* uri, const char* /*mode*/) override {
    if (uri == nullptr || std::strcmp(uri, kUri) != 0 || !state_.online.load() ||
        state_.stale.load()) {
      return nullptr;
    }
    return new (std::nothrow) SimDepthDevice(&state_);
  }
  void deviceClose(oni::driver::DeviceBase* device) override { delete device; }

  OniStatus tryDevice(const char* uri) override {
    return (uri != nullptr && std::strcmp(uri, kUri) == 0) ? ONI_STATUS_OK : ONI_STATUS_ERROR;
  }

  void shutdown() override {
    {
      std::lock_guard<std::mutex> lock(mu_);
      running_ = false;
    }
    cv_.notify_all();
    if (watcher_.joinable()) watcher_.join();
  }

 private:
  // Unplugs the device after `disconnect_after` frames, plugs it back after `offline_ms`; or
  // follows the unplugged file.
  void Watch() {
    std::unique_lock<std::mutex> lock(mu_);
    while (running_) {
      cv_.wait_for(lock, std::chrono::milliseconds(10), [this] { return !running_; });
      if (!running_) break;
      if (!unplugged_file_.empty()) {
        const bool plugged = !FileExists(unplugged_file_);
        if (plugged == state_.online.load()) continue;
        state_.online = plugged;
        if (!hotplug_) {
          // Such a driver's handle on the device dies with the unplugging: only a driver
          // loaded afterwards finds it again.
          if (!plugged) state_.stale = true;
          continue;
        }
        lock.unlock();
        if (plugged) {
          deviceConnected(&info_);
        } else {
          deviceDisconnected(&info_);
        }
        lock.lock();
        continue;
      }
      if (state_.online.load() && state_.frames_served.load() >= state_.disconnect_after) {
        state_.online = false;
        lock.unlock();
        deviceDisconnected(&info_);
        lock.lock();
        cv_.wait_for(lock, std::chrono::milliseconds(state_.offline_ms),
                     [this] { return !running_; });
        if (!running_) break;
        state_.frames_served = 0;
        state_.online = true;
        lock.unlock();
        deviceConnected(&info_);
        lock.lock();
      }
    }
  }

  DeviceState state_;
  OniDeviceInfo info_{};
  std::string unplugged_file_;  // see HPOSE_SIM_DEPTH_UNPLUGGED_FILE.
  bool hotplug_ = true;         // devices announced as they come and go, not only at load.
  std::mutex mu_;
  std::condition_variable cv_;
  bool running_ = false;
  std::thread watcher_;
};

}  // namespace

ONI_EXPORT_DRIVER(SimDepthDriver)
