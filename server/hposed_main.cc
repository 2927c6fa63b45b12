// hposed: the hpose daemon. Estimates the humanoid's pose in every frame of its source (an
// OpenNI2 device or a recording) and serves the estimates over gRPC (hpose.v1.PoseService).
#include <cmath>
#include <csignal>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <malloc.h>
#include <pthread.h>
#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>

#include "core/common/vector_level.h"
#include "core/search/vector_paths.h"
#include "server/daemon.h"
#include "server/daemon_config.h"
#include "tools/exit_codes.h"
#include "tools/flag_parser.h"
#include "tools/template_paths.h"

namespace {

using hpose::tools::FlagParser;

// "X,Y,YAW" (metres, metres, radians) -> world_from_ground.
bool ParseWorldFromGround(const std::string& text, hpose::server::WorldFrameConfig* out) {
  double x = 0.0, y = 0.0, yaw = 0.0;
  char c1 = 0, c2 = 0, extra = 0;
  std::istringstream in(text);
  if (!(in >> x >> c1 >> y >> c2 >> yaw) || c1 != ',' || c2 != ',' || (in >> extra)) return false;
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(yaw)) return false;
  out->configured = true;
  out->x_m = x;
  out->y_m = y;
  out->yaw_rad = yaw;
  return true;
}

// Log lines on stdout: ISO 8601 time with milliseconds, level, message; flushed at once (the
// lines are rare: state changes, clients, never one per frame at info).
bool SetUpLogging(const std::string& level_name) {
  const spdlog::level::level_enum level = spdlog::level::from_str(level_name);
  if (level == spdlog::level::off && level_name != "off") return false;
  auto logger = spdlog::stdout_logger_mt("hposed");
  logger->set_pattern("%Y-%m-%dT%H:%M:%S.%e%z %l %v");
  logger->set_level(level);
  logger->flush_on(spdlog::level::trace);
  spdlog::set_default_logger(logger);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  // Requests, clouds and their copies are megabytes each: a fixed mmap threshold gives every
  // such buffer back to the system when freed. glibc's default raises the threshold after the
  // first large free, and the heap arenas of many handler threads then keep a flood of large
  // requests' memory resident long after it was released.
  mallopt(M_MMAP_THRESHOLD, 1 << 20);
  std::string config_path, listen, source, rate, intrinsics;
  std::string stereo_source, stereo_calibration, stereo_options, world_from_ground;
  std::vector<std::string> templates;
  std::string tls_cert, tls_key, tls_client_ca, token_file, http, log_level = "info";
  bool loop = false, print_config = false, insecure = false;
  double fps = 30.0, stereo_fps = 15.0;
  FlagParser flags(
      "hposed [--config FILE.yaml] [--listen ADDR] [--source PATH] [--template FILE.bt ...] "
      "[--stereo-source DIR] [--world-from-ground X,Y,YAW]",
      "Serves humanoid pose estimates over gRPC (hpose.v1.PoseService, plus grpc.health.v1 and "
      "server reflection). PATH is openni2:// (any OpenNI2 device; openni2://URI for one), an "
      ".oni recording, a directory of 16-bit depth frames (PNG with intrinsics.json, TIFF, or "
      "PCL's *_depth.pclzf with their .xml), a directory of PCD clouds, or a single frame file. "
      "A stereo source (a directory of left/right frame pairs) runs the "
      "stereo-marker estimator beside the depth source, or alone; its estimates go out through "
      "the same calls, marked with their estimator. Flags override the config file. "
      "HPOSE_VECTOR_LEVEL=avx2 or scalar in the environment caps the estimator's vector paths "
      "(the same estimates; the start-up log names the paths taken).");
  flags.AddString("config", &config_path, "YAML config file (see server/hposed.example.yaml)",
                  "FILE");
  flags.AddString("listen", &listen, "address to serve on (default 127.0.0.1:50051)", "ADDR");
  flags.AddString("source", &source, "frame source (see above)", "PATH");
  flags.AddString("http", &http,
                  "serve the live web view, its JSON, /metrics and /healthz over plain HTTP on "
                  "ADDR (e.g. 127.0.0.1:8080; port 0 picks one); off by default, a non-loopback "
                  "address needs --insecure (docs/WEB.md)",
                  "ADDR");
  flags.AddString("log-level", &log_level,
                  "trace, debug, info (default: state changes and clients), warn, err, critical "
                  "or off",
                  "LEVEL");
  flags.AddString("intrinsics", &intrinsics,
                  "the depth camera's intrinsics for every frame (hpose intrinsics.json or a ROS "
                  "camera_info YAML), e.g. a calibrated camera on openni2://; default: what the "
                  "source knows (OpenNI2: its field of view, principal point at the image centre)",
                  "FILE");
  flags.AddStrings(
      "template", &templates,
      "humanoid template: a .bt file or a shipped template's name (default: the shipped templates)",
      "FILE.bt");
  flags.AddString("rate", &rate, "replay rate of recordings: recorded or fast", "RATE");
  flags.AddBool("loop", &loop, "replay recordings in a loop");
  flags.AddDouble("fps", &fps, "frame rate of PNG/PCD directories (Hz)", "HZ");
  flags.AddString("stereo-source", &stereo_source,
                  "directory of stereo pairs (DIR/frames.csv or DIR/left + DIR/right, as written "
                  "by `hpose simulate stereo`)",
                  "DIR");
  flags.AddString("stereo-calibration", &stereo_calibration,
                  "OpenCV stereo calibration (default DIR/calibration.yaml); alone, it enables "
                  "the EstimateStereo call",
                  "FILE");
  flags.AddString("stereo-options", &stereo_options,
                  "stereo estimator options (landmarks, colours, thresholds)", "FILE");
  flags.AddDouble("stereo-fps", &stereo_fps, "rate of stereo directories without frames.csv", "HZ");
  flags.Within("stereo-fps", 0.01, 10000.0);  // as stereo.fps in a config.
  flags.AddString("world-from-ground", &world_from_ground,
                  "the depth sensor's ground frame in the world (landmark) frame: its origin "
                  "X,Y in metres and its yaw in radians; depth poses are then also reported in "
                  "the world frame",
                  "X,Y,YAW");
  flags.AddString("tls-cert", &tls_cert, "PEM server certificate: serve TLS (with --tls-key)",
                  "FILE");
  flags.AddString("tls-key", &tls_key, "PEM private key of --tls-cert", "FILE");
  flags.AddString("tls-client-ca", &tls_client_ca,
                  "PEM CA: mutual TLS, clients must present a certificate it signed", "FILE");
  flags.AddString("token-file", &token_file,
                  "bearer tokens, one 'TOKEN ROLE' per line (ROLE read or estimate); every call "
                  "must then carry 'authorization: Bearer TOKEN'",
                  "FILE");
  flags.AddBool("insecure", &insecure,
                "serve a non-loopback --listen address without TLS (refused otherwise)");
  flags.AddBool("print-config", &print_config, "print the effective config as YAML and exit");
  flags.SetEpilog(
      "examples:\n"
      "  hposed --source recording.oni --loop --template templates/standing.bt\n"
      "  hposed --source openni2:// --template templates/standing.bt "
      "--template templates/right_arm_raised.bt\n"
      "  hposed --source openni2:// --stereo-source stereo_run/ "
      "--world-from-ground 0,-2,1.5708\n"
      "  hposed --source openni2:// --http 127.0.0.1:8080   (then open http://127.0.0.1:8080/)\n"
      "--loop and --rate apply to both sources.\n"
      "SIGINT or SIGTERM shut the daemon down cleanly.\n");
  if (const int code = flags.ParseOrExitCode(argc, argv); code >= 0) return code;
  if (!SetUpLogging(log_level)) {
    std::cerr << "hposed: --log-level: expected trace, debug, info, warn, err, critical or off, "
                 "got '"
              << log_level << "'\n";
    return hpose::tools::kExitUsage;
  }

  const hpose::Status vector_level = hpose::CheckVectorLevelVariable();
  if (!vector_level.ok()) return hpose::tools::ReportProgramError("hposed", vector_level.error());

  hpose::server::DaemonConfig config;
  if (!config_path.empty()) {
    hpose::Result<hpose::server::DaemonConfig> loaded =
        hpose::server::LoadDaemonConfig(config_path);
    if (!loaded.ok()) return hpose::tools::ReportProgramError("hposed", loaded.error());
    config = std::move(*loaded);
  }
  if (flags.Seen("listen")) config.grpc.listen = listen;
  if (flags.Seen("http")) config.http.listen = http;
  if (flags.Seen("tls-cert")) config.security.tls_cert = tls_cert;
  if (flags.Seen("tls-key")) config.security.tls_key = tls_key;
  if (flags.Seen("tls-client-ca")) config.security.tls_client_ca = tls_client_ca;
  if (flags.Seen("token-file")) config.security.tokens_file = token_file;
  if (flags.Seen("insecure")) config.security.insecure = insecure;
  if (flags.Seen("source")) config.source.path = source;
  if (flags.Seen("intrinsics")) config.source.intrinsics = intrinsics;
  if (flags.Seen("template")) config.templates = templates;
  if (flags.Seen("loop")) config.source.loop = config.stereo.loop = loop;
  if (flags.Seen("fps")) {
    if (!(fps > 0.0 && fps <= 10000.0)) {
      std::cerr << "hposed: --fps: the replay rate must be more than 0 and at most 10000 frames "
                   "per second, "
                   "got "
                << fps << "\n";
      return hpose::tools::kExitUsage;
    }
    config.source.fps = fps;
  }
  if (flags.Seen("rate")) {
    if (rate != "recorded" && rate != "fast") {
      std::cerr << "hposed: --rate: expected 'recorded' or 'fast', got '" << rate << "'\n";
      return hpose::tools::kExitUsage;
    }
    config.source.realtime = config.stereo.realtime = rate == "recorded";
  }
  if (flags.Seen("stereo-source")) config.stereo.source = stereo_source;
  if (flags.Seen("stereo-calibration")) config.stereo.calibration = stereo_calibration;
  if (flags.Seen("stereo-options")) config.stereo.options = stereo_options;
  if (flags.Seen("stereo-fps")) config.stereo.fps = stereo_fps;
  if (flags.Seen("world-from-ground") &&
      !ParseWorldFromGround(world_from_ground, &config.world_from_ground)) {
    std::cerr << "hposed: --world-from-ground: expected X,Y,YAW (metres, metres, radians), got '"
              << world_from_ground << "'\n";
    return hpose::tools::kExitUsage;
  }
  // Without templates in the config or on the command line, the shipped ones are used.
  if (config.templates.empty()) config.templates = hpose::tools::DefaultTemplatePaths();
  const hpose::Status names = hpose::tools::CheckTemplateNames(config.templates);
  config.templates = hpose::tools::ResolveTemplateNames(config.templates);
  if (print_config) {
    std::cout << hpose::server::DaemonConfigToYaml(config);
    hpose::Status valid = hpose::server::ValidateDaemonConfig(config);
    if (!valid.ok()) return hpose::tools::ReportProgramError("hposed", valid.error());
    return hpose::tools::kExitOk;
  }
  if (!names.ok()) return hpose::tools::ReportProgramError("hposed", names.error());

  // Block the shutdown signals in every thread (gRPC's and ours inherit the mask); the main
  // thread waits for them below.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  hpose::Result<std::unique_ptr<hpose::server::Daemon>> daemon =
      hpose::server::Daemon::Start(config);
  if (!daemon.ok()) return hpose::tools::ReportProgramError("hposed", daemon.error());
  spdlog::info(
      "hposed: listening on {} with {} template(s) searched on {:.1f} mm voxels, source "
      "{}, stereo source {}",
      (*daemon)->address(), config.templates.size(), 1000.0 * (*daemon)->search_resolution_m(),
      config.source.path.empty() ? "(none)" : config.source.path,
      config.stereo.source.empty() ? "(none)" : config.stereo.source);
  if (!hpose::server::IsLoopbackListen(config.grpc.listen) &&
      config.security.tls_client_ca.empty()) {
    spdlog::warn(
        "hposed: {} is served to other machines without mutual TLS: any peer that connects "
        "reaches gRPC's HTTP/2 parser before a token is checked, and with Debian bookworm's gRPC "
        "(1.51) one client can make the daemon hold memory without bound (docs/RELIABILITY.md, "
        "\"Connections\"); on a network you do not trust, require client certificates "
        "(--tls-client-ca)",
        (*daemon)->address());
  }
  spdlog::info("hposed: vector paths: {}", hpose::VectorPathsInUse());
  if ((*daemon)->http_port() > 0) {
    spdlog::info("hposed: web view on http://{}/ (metrics on /metrics)", (*daemon)->http_address());
  }

  int sig = 0;
  sigwait(&signals, &sig);
  spdlog::info("hposed: {}, shutting down", sig == SIGINT ? "SIGINT" : "SIGTERM");
  (*daemon)->Shutdown();
  spdlog::info("hposed: stopped");
  return hpose::tools::kExitOk;
}
