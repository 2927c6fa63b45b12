// `hpose record`: records depth from an OpenNI2 device to an .oni file or a PNG directory.
#include <atomic>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <string>

#include "server/openni2_recorder.h"
#include "tools/command.h"
#include "tools/exit_codes.h"
#include "tools/flag_parser.h"

namespace hpose::tools {

namespace {

std::atomic<bool> g_stop{false};

void OnStopSignal(int) { g_stop = true; }

}  // namespace

int RunRecord(int argc, char** argv) {
  std::string device = "openni2://", out;
  int frames = 0;
  double duration_s = 0.0, timeout_s = 5.0;
  bool quiet = false;
  FlagParser flags(
      "hpose record --out FILE.oni|DIR [--device openni2://[URI]] [--frames N] [--duration S]",
      "Records depth frames from an OpenNI2 device. An --out ending in .oni is written by "
      "OpenNI2's recorder (replayable by hposed, hpose replay and any OpenNI2 tool); anything "
      "else is a directory of 16-bit PNG frames in millimetres plus intrinsics.json (from the "
      "stream's field of view). Stops after --frames, --duration or Ctrl-C.");
  flags.AddString("out", &out, "output .oni file or directory", "PATH");
  flags.AddString("device", &device, "openni2:// (any device) or openni2://URI", "SPEC");
  flags.AddInt("frames", &frames, "number of frames (0 = no limit)", "N");
  flags.AddDouble("duration", &duration_s, "seconds to record (0 = no limit)", "S");
  flags.AddDouble("timeout", &timeout_s, "fail when no frame arrives for this long, seconds", "S");
  flags.AddBool("quiet", &quiet, "no progress output");
  flags.SetEpilog(
      "examples:\n  hpose record --out walk.oni --duration 10\n"
      "  hpose record --out frames/ --frames 300\n");
  if (const int code = flags.ParseOrExitCode(argc, argv); code >= 0) return code;
  if (out.empty()) {
    std::cerr << flags.Help() << "\nerror: --out is required\n";
    return kExitUsage;
  }
  if (frames < 0 || duration_s < 0 || !(timeout_s > 0)) {
    std::cerr << "hpose record: --frames and --duration must be >= 0, --timeout > 0\n";
    return kExitUsage;
  }
  std::signal(SIGINT, OnStopSignal);
  std::signal(SIGTERM, OnStopSignal);
  server::RecordOptions options;
  options.frames = frames;
  options.duration_s = duration_s;
  options.frame_timeout_s = timeout_s;
  Result<server::RecordSummary> summary = server::RecordOpenni2(device, out, options, [&](long n) {
    if (!quiet && (n % 30 == 0)) std::fprintf(stderr, "\rrecorded %ld frame(s)", n);
    return !g_stop.load();
  });
  if (!quiet) std::fprintf(stderr, "\r");
  if (!summary.ok()) return ReportError("record", summary.error());
  std::printf("recorded %ld frame(s) in %.1f s to %s (%s)\n", summary->frames, summary->duration_s,
              out.c_str(), summary->format.c_str());
  return kExitOk;
}

}  // namespace hpose::tools
