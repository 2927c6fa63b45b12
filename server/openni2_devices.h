#ifndef HPOSE_SERVER_OPENNI2_DEVICES_H_
#define HPOSE_SERVER_OPENNI2_DEVICES_H_

#include <string>
#include <vector>

#include "core/common/status.h"

namespace openni {
class Device;
class VideoStream;
}  // namespace openni

namespace hpose::server {

// One video mode of a depth sensor.
struct Openni2DepthMode {
  int width = 0;
  int height = 0;
  int fps = 0;
  std::string units;  // "1 mm", "100 um", or the OpenNI2 pixel format's number.
};

// What OpenNI2 reports of one device it sees: its identity, and, when it opens, its depth
// stream as it would start.
struct Openni2DeviceReport {
  std::string uri;  // openni2://URI opens it.
  std::string name;
  std::string vendor;
  int usb_vendor_id = 0;
  int usb_product_id = 0;
  std::string open_error;     // empty when it opened.
  std::string other_sensors;  // "colour and infrared", "" for none.
  bool has_depth = false;
  std::vector<Openni2DepthMode> depth_modes;
  Openni2DepthMode current;  // the mode the stream starts in.
  int preferred = -1;        // of depth_modes, the one hpose streams in (PreferredDepthMode).
  double horizontal_fov_deg = 0.0;
  double vertical_fov_deg = 0.0;
  bool mirrored = false;
  bool cropped = false;
  bool registered = false;  // depth registered to the colour camera.
};

// Every device OpenNI2's drivers see now, opened one by one. An error only when OpenNI2 itself
// cannot start; no device is an empty list.
Result<std::vector<Openni2DeviceReport>> ListOpenni2Devices();

// Of a depth sensor's `modes`, the index of the one to stream in, or -1 when none is in 1 mm or
// 100 um units. With `want_width` x `want_height` (the size of given intrinsics) a mode of that
// size comes first. Then: at most 640 pixels wide (a Kinect v1's depth image; wider modes cost
// more than a frame period), 30 frames a second or more, the most pixels (PS1080's driver starts
// in 320x240, at which heading and far robots suffer), the most frames a second, and 1 mm before
// 100 um.
int PreferredDepthMode(const std::vector<Openni2DepthMode>& modes, int want_width = 0,
                       int want_height = 0);

// Sets a created, not yet started depth `stream` to its PreferredDepthMode; leaves it as it is
// when that is the current one or none qualifies.
void SelectPreferredDepthMode(openni::VideoStream& stream, int want_width = 0, int want_height = 0);

// Switches off a live `device`'s registration of depth to its colour camera (PS1080's
// Registration=1): registered depth is drawn from the colour camera's place, whose focal length
// differs from the depth field of view OpenNI2 reports by some 10%, and hpose needs no colour.
void KeepDepthUnregistered(openni::Device& device);

// "no OpenNI2 device found" (an empty `uri`: any device) or "OpenNI2 device 'URI' not found",
// with where to look next.
std::string DeviceNotFound(const std::string& uri);

}  // namespace hpose::server

#endif  // HPOSE_SERVER_OPENNI2_DEVICES_H_
