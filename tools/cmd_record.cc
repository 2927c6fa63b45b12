// `hpose record`: records depth from an OpenNI2 device to an .oni file or a PNG directory.
#include <atomic>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <string>

#include "core/common/clock_limits.h"
#include "server/openni2_recorder.h"
#include "tools/cmd_record_flags.h"
#include "tools/command.h"
#include "tools/exit_codes.h"
#include "tools/flag_parser.h"

namespace hpose::tools {

namespace {

std::atomic<bool> g_stop{false};

void OnStopSignal(int) { g_stop = true; }

}  // namespace

int RunRecord(int argc, char** argv) {
  RecordFlags f;
  FlagParser flags = f.Parser();
  if (const int code = flags.ParseOrExitCode(argc, argv); code >= 0) return code;
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
