// `hpose record`: records depth from an OpenNI2 device to an .oni file or a PNG directory.
#include <atomic>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "core/common/clock_limits.h"
#include "server/openni2_devices.h"
#include "server/openni2_recorder.h"
#include "tools/cmd_record_flags.h"
#include "tools/command.h"
#include "tools/exit_codes.h"
#include "tools/flag_parser.h"

namespace hpose::tools {

namespace {

std::atomic<bool> g_stop{false};

void OnStopSignal(int) { g_stop = true; }

std::string UsbIds(const server::Openni2DeviceReport& d) {
  char ids[32];
  std::snprintf(ids, sizeof(ids), "USB %04x:%04x", d.usb_vendor_id & 0xffff,
                d.usb_product_id & 0xffff);
  return ids;
}

std::string ModeText(const server::Openni2DepthMode& m) {
  return std::to_string(m.width) + "x" + std::to_string(m.height) + " at " + std::to_string(m.fps) +
         " fps in " + m.units;
}

// `hpose record --list-devices`: what OpenNI2's drivers see, or why there may be nothing.
int ListDevices() {
  Result<std::vector<server::Openni2DeviceReport>> devices = server::ListOpenni2Devices();
  if (!devices.ok()) return ReportError("record", devices.error());
  if (devices->empty()) {
    std::cerr << "hpose record: no OpenNI2 device found. Is the camera plugged in and powered, "
                 "and is its OpenNI2 driver installed? Debian's libopenni2-0 brings PS1080's "
                 "(PrimeSense, Asus Xtion); a Microsoft Kinect v1 needs libfreenect's OpenNI2 "
                 "driver (libFreenectDriver.so, built from libfreenect's source) in OpenNI2's "
                 "Drivers directory. The user also needs the USB device: Debian's udev rules "
                 "give depth cameras to the group video.\n";
    return kExitUnavailable;
  }
  for (const server::Openni2DeviceReport& d : *devices) {
    std::printf("openni2://%s\n  %s (%s), %s\n", d.uri.c_str(), d.name.c_str(), d.vendor.c_str(),
                UsbIds(d).c_str());
    if (!d.open_error.empty()) {
      std::printf("  cannot be opened: %s\n", d.open_error.c_str());
      continue;
    }
    if (!d.has_depth) {
      std::printf(
          "  no depth stream (%s)\n",
          d.other_sensors.empty() ? "no stream" : ("it has " + d.other_sensors + " only").c_str());
      continue;
    }
    std::printf("  depth: field of view %.1f x %.1f deg%s%s%s\n", d.horizontal_fov_deg,
                d.vertical_fov_deg, d.mirrored ? ", mirrored (hpose reads it unmirrored)" : "",
                d.cropped ? ", cropped (hpose keeps each pixel's ray)" : "",
                d.registered ? ", registered to the colour camera (hpose switches it off)" : "");
    for (size_t i = 0; i < d.depth_modes.size(); ++i) {
      const server::Openni2DepthMode& m = d.depth_modes[i];
      const bool starts = m.width == d.current.width && m.height == d.current.height &&
                          m.fps == d.current.fps && m.units == d.current.units;
      const bool chosen = static_cast<int>(i) == d.preferred;
      std::printf("    %s%s%s\n", ModeText(m).c_str(), starts ? "  (the device starts in it)" : "",
                  chosen ? "  (hpose streams in it)" : "");
    }
    if (!d.other_sensors.empty()) std::printf("  also: %s\n", d.other_sensors.c_str());
  }
  return kExitOk;
}

}  // namespace

int RunRecord(int argc, char** argv) {
  RecordFlags f;
  FlagParser flags = f.Parser();
  if (const int code = flags.ParseOrExitCode(argc, argv); code >= 0) return code;
  if (f.list_devices) return ListDevices();
  if (f.out.empty()) {
    std::cerr << flags.Help() << "\nerror: --out is required\n";
    return kExitUsage;
  }
  if (f.frames < 0 || !(f.duration_s >= 0) || !WaitInRange(f.timeout_s)) {
    std::cerr << "hpose record: --frames and --duration must be >= 0, --timeout in (0, 86400] "
                 "seconds\n";
    return kExitUsage;
  }
  std::signal(SIGINT, OnStopSignal);
  std::signal(SIGTERM, OnStopSignal);
  server::RecordOptions options;
  options.frames = f.frames;
  options.duration_s = f.duration_s;
  options.frame_timeout_s = f.timeout_s;
  Result<server::RecordSummary> summary =
      server::RecordOpenni2(f.device, f.out, options, [&](long n) {
        if (!f.quiet && (n % 30 == 0)) std::fprintf(stderr, "\rrecorded %ld frame(s)", n);
        return !g_stop.load();
      });
  if (!f.quiet) std::fprintf(stderr, "\r");
  if (!summary.ok()) return ReportError("record", summary.error());
  std::printf("recorded %ld frame(s) in %.1f s to %s (%s)\n", summary->frames, summary->duration_s,
              f.out.c_str(), summary->format.c_str());
  return kExitOk;
}

}  // namespace hpose::tools
