#include "tools/cmd_record_flags.h"

namespace hpose::tools {

FlagParser RecordFlags::Parser() {
  FlagParser flags(
      "hpose record --out FILE.oni|DIR [--device openni2://[URI]] [--frames N] [--duration S]\n"
      "       hpose record --list-devices",
      "Records depth frames from an OpenNI2 device. An --out ending in .oni is written by "
      "OpenNI2's recorder (replayable by hposed, hpose replay and any OpenNI2 tool); anything "
      "else is a directory of 16-bit PNG frames in millimetres plus intrinsics.json (from the "
      "stream's field of view). The device streams depth as hposed would take it: its mode with "
      "the most pixels up to 640x480 at 30 fps (--list-devices shows which), registration to "
      "the colour camera off. Stops after --frames, --duration or Ctrl-C. OpenNI2's recorder "
      "keeps every frame the device sends while it runs, so an .oni file holds at least --frames "
      "(usually exactly; more when frames arrive while it stops or while a read is late); the "
      "count printed is the file's. An .oni replaces a file of that name only once finished; a "
      "directory must not hold a recording already. When the device stops sending, the frames "
      "before are kept and the error says where.");
  flags.AddString("out", &out, "output .oni file or directory", "PATH");
  flags.AddString("device", &device, "openni2:// (any device) or openni2://URI", "SPEC");
  flags.AddInt("frames", &frames, "number of frames (0 = no limit)", "N");
  flags.AddDouble("duration", &duration_s, "seconds to record (0 = no limit)", "S");
  flags.AddDouble("timeout", &timeout_s, "fail when no frame arrives for this long, seconds", "S");
  flags.AddBool("quiet", &quiet, "no progress output");
  flags.AddBool("list-devices", &list_devices,
                "list the devices OpenNI2 sees (URI, USB ids, depth modes, field of view, "
                "mirroring) and exit; 5 when there is none");
  flags.SetEpilog(
      "examples:\n  hpose record --list-devices\n"
      "  hpose record --out walk.oni --duration 10\n"
      "  hpose record --out frames/ --frames 300\n");
  return flags;
}

}  // namespace hpose::tools
