#include "server/openni2_devices.h"

#include <OpenNI.h>

#include <cmath>

#include "core/common/pose2d.h"
#include "server/openni2_sensors.h"

namespace hpose::server {

namespace {

std::string Units(openni::PixelFormat format) {
  switch (format) {
    case openni::PIXEL_FORMAT_DEPTH_1_MM:
      return "1 mm";
    case openni::PIXEL_FORMAT_DEPTH_100_UM:
      return "100 um";
    default:
      return "pixel format " + std::to_string(static_cast<int>(format));
  }
}

Openni2DepthMode Mode(const openni::VideoMode& m) {
  Openni2DepthMode out;
  out.width = m.getResolutionX();
  out.height = m.getResolutionY();
  out.fps = m.getFps();
  out.units = Units(m.getPixelFormat());
  return out;
}

std::vector<Openni2DepthMode> Modes(const openni::Array<openni::VideoMode>& modes) {
  std::vector<Openni2DepthMode> out;
  for (int i = 0; i < modes.getSize(); ++i) out.push_back(Mode(modes[i]));
  return out;
}

// Opens the device and fills in its depth stream as it would start.
void Inspect(Openni2DeviceReport* report) {
  openni::Device device;
  if (device.open(report->uri.c_str()) != openni::STATUS_OK) {
    report->open_error = WithOpenni2Error("OpenNI2 cannot open it");
    return;
  }
  report->other_sensors = ColourAndInfraredSensors(device);
  report->registered =
      device.getImageRegistrationMode() == openni::IMAGE_REGISTRATION_DEPTH_TO_COLOR;
  report->has_depth = device.hasSensor(openni::SENSOR_DEPTH);
  if (report->has_depth) {
    const openni::SensorInfo* info = device.getSensorInfo(openni::SENSOR_DEPTH);
    report->depth_modes = Modes(info->getSupportedVideoModes());
    report->preferred = PreferredDepthMode(report->depth_modes);
    openni::VideoStream depth;
    if (depth.create(device, openni::SENSOR_DEPTH) == openni::STATUS_OK) {
      report->current = Mode(depth.getVideoMode());
      report->horizontal_fov_deg = RadToDeg(depth.getHorizontalFieldOfView());
      report->vertical_fov_deg = RadToDeg(depth.getVerticalFieldOfView());
      report->mirrored = depth.getMirroringEnabled();
      int x = 0, y = 0, w = 0, h = 0;
      report->cropped = depth.getCropping(&x, &y, &w, &h);
      depth.destroy();
    }
  }
  device.close();
}

}  // namespace

Result<std::vector<Openni2DeviceReport>> ListOpenni2Devices() {
  if (openni::OpenNI::initialize() != openni::STATUS_OK) {
    return MakeError(ErrorCode::kUnavailable, WithOpenni2Error("OpenNI2 failed to initialise"));
  }
  std::vector<Openni2DeviceReport> reports;
  {
    openni::Array<openni::DeviceInfo> devices;
    openni::OpenNI::enumerateDevices(&devices);
    for (int i = 0; i < devices.getSize(); ++i) {
      Openni2DeviceReport r;
      r.uri = devices[i].getUri();
      r.name = devices[i].getName();
      r.vendor = devices[i].getVendor();
      r.usb_vendor_id = devices[i].getUsbVendorId();
      r.usb_product_id = devices[i].getUsbProductId();
      Inspect(&r);
      reports.push_back(std::move(r));
    }
  }
  openni::OpenNI::shutdown();
  return reports;
}

int PreferredDepthMode(const std::vector<Openni2DepthMode>& modes, int want_width,
                       int want_height) {
  constexpr int kWidestWidth = 640;
  constexpr int kFrameRate = 30;
  int best = -1;
  std::vector<long> best_key;
  for (size_t i = 0; i < modes.size(); ++i) {
    const Openni2DepthMode& m = modes[i];
    const bool mm = m.units == "1 mm";
    if (!mm && m.units != "100 um") continue;
    const std::vector<long> key = {
        (want_width > 0 && m.width == want_width && m.height == want_height) ? 1 : 0,
        m.width <= kWidestWidth ? 1 : 0,
        m.fps >= kFrameRate ? 1 : 0,
        static_cast<long>(m.width) * m.height * (m.width <= kWidestWidth ? 1 : -1),
        m.fps,
        mm ? 1 : 0};
    if (best < 0 || key > best_key) {
      best = static_cast<int>(i);
      best_key = key;
    }
  }
  return best;
}

void SelectPreferredDepthMode(openni::VideoStream& stream, int want_width, int want_height) {
  const openni::Array<openni::VideoMode>& modes = stream.getSensorInfo().getSupportedVideoModes();
  const int preferred = PreferredDepthMode(Modes(modes), want_width, want_height);
  if (preferred < 0) return;
  const openni::VideoMode current = stream.getVideoMode();
  const openni::VideoMode& want = modes[preferred];
  if (current.getResolutionX() == want.getResolutionX() &&
      current.getResolutionY() == want.getResolutionY() && current.getFps() == want.getFps() &&
      current.getPixelFormat() == want.getPixelFormat()) {
    return;
  }
  stream.setVideoMode(want);  // a device that refuses keeps its mode: still a depth stream.
}

void KeepDepthUnregistered(openni::Device& device) {
  if (device.getImageRegistrationMode() != openni::IMAGE_REGISTRATION_OFF) {
    device.setImageRegistrationMode(openni::IMAGE_REGISTRATION_OFF);
  }
}

std::string DeviceNotFound(const std::string& uri) {
  return (uri.empty() ? std::string("no OpenNI2 device found")
                      : "OpenNI2 device '" + uri + "' not found") +
         " (`hpose record --list-devices` lists the devices OpenNI2 sees)";
}

}  // namespace hpose::server
