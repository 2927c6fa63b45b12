// hposed: the hpose daemon. Estimates the humanoid's pose in every frame of its source (an
// OpenNI2 device or a recording) and serves the estimates over gRPC (hpose.v1.PoseService).
#include <csignal>
#include <iostream>
#include <string>
#include <vector>

#include <pthread.h>

#include "server/daemon.h"
#include "server/daemon_config.h"
#include "tools/exit_codes.h"
#include "tools/flag_parser.h"
#include "tools/template_paths.h"

namespace {

using hpose::tools::FlagParser;

}  // namespace

int main(int argc, char** argv) {
  std::string config_path, listen, source, rate;
  std::vector<std::string> templates;
  bool loop = false, print_config = false;
  double fps = 30.0;
  FlagParser flags(
      "hposed [--config FILE.yaml] [--listen ADDR] [--source PATH] [--template FILE.bt ...]",
      "Serves humanoid pose estimates over gRPC (hpose.v1.PoseService, plus grpc.health.v1 and "
      "server reflection). PATH is an .oni recording, a directory of 16-bit PNG depth frames "
      "with intrinsics.json, a directory of PCD clouds, or openni2:// (any OpenNI2 device; "
      "openni2://URI for one). Flags override the config file.");
  flags.AddString("config", &config_path, "YAML config file (see server/hposed.example.yaml)",
                  "FILE");
  flags.AddString("listen", &listen, "address to serve on (default 127.0.0.1:50051)", "ADDR");
  flags.AddString("source", &source, "frame source (see above)", "PATH");
  flags.AddStrings("template", &templates,
                   "humanoid template, repeatable (default: the shipped templates)", "FILE.bt");
  flags.AddString("rate", &rate, "replay rate of recordings: recorded or fast", "RATE");
  flags.AddBool("loop", &loop, "replay recordings in a loop");
  flags.AddDouble("fps", &fps, "frame rate of PNG/PCD directories (Hz)", "HZ");
  flags.AddBool("print-config", &print_config, "print the effective config as YAML and exit");
  flags.SetEpilog(
      "examples:\n"
      "  hposed --source recording.oni --loop --template templates/standing.bt\n"
      "  hposed --source openni2:// --template templates/standing.bt "
      "--template templates/right_arm_raised.bt\n"
      "SIGINT or SIGTERM shut the daemon down cleanly.\n");
  switch (flags.Parse(argc, argv)) {
    case FlagParser::Outcome::kHelpShown:
      return hpose::tools::kExitOk;
    case FlagParser::Outcome::kError:
      return hpose::tools::kExitUsage;
    case FlagParser::Outcome::kOk:
      break;
  }

  hpose::server::DaemonConfig config;
  if (!config_path.empty()) {
    hpose::Result<hpose::server::DaemonConfig> loaded =
        hpose::server::LoadDaemonConfig(config_path);
    if (!loaded.ok()) return hpose::tools::ReportError("hposed", loaded.error());
    config = std::move(*loaded);
  }
  if (flags.Seen("listen")) config.grpc.listen = listen;
  if (flags.Seen("source")) config.source.path = source;
  if (flags.Seen("template")) config.templates = templates;
  if (flags.Seen("loop")) config.source.loop = loop;
  if (flags.Seen("fps")) config.source.fps = fps;
  if (flags.Seen("rate")) {
    if (rate != "recorded" && rate != "fast") {
      std::cerr << "hposed: --rate: expected 'recorded' or 'fast', got '" << rate << "'\n";
      return hpose::tools::kExitUsage;
    }
    config.source.realtime = rate == "recorded";
  }
  // Without templates in the config or on the command line, the shipped ones are used.
  if (config.templates.empty()) config.templates = hpose::tools::DefaultTemplatePaths();
  if (print_config) {
    std::cout << hpose::server::DaemonConfigToYaml(config);
    hpose::Status valid = hpose::server::ValidateDaemonConfig(config);
    if (!valid.ok()) return hpose::tools::ReportError("hposed", valid.error());
    return hpose::tools::kExitOk;
  }

  // Block the shutdown signals in every thread (gRPC's and ours inherit the mask); the main
  // thread waits for them below.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  hpose::Result<std::unique_ptr<hpose::server::Daemon>> daemon =
      hpose::server::Daemon::Start(config);
  if (!daemon.ok()) return hpose::tools::ReportError("hposed", daemon.error());
  std::cout << "hposed: listening on " << (*daemon)->address() << " with "
            << config.templates.size() << " template(s), source "
            << (config.source.path.empty() ? "(none)" : config.source.path) << std::endl;

  int sig = 0;
  sigwait(&signals, &sig);
  std::cout << "hposed: " << (sig == SIGINT ? "SIGINT" : "SIGTERM") << ", shutting down"
            << std::endl;
  (*daemon)->Shutdown();
  std::cout << "hposed: stopped" << std::endl;
  return hpose::tools::kExitOk;
}
