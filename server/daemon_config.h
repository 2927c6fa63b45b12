#ifndef HPOSE_SERVER_DAEMON_CONFIG_H_
#define HPOSE_SERVER_DAEMON_CONFIG_H_

#include <cstdint>
#include <string>
#include <vector>

#include "core/common/status.h"
#include "core/search/estimator.h"

namespace hpose::server {

// gRPC endpoint settings.
struct GrpcConfig {
  std::string listen = "127.0.0.1:50051";    // loopback by default; "0.0.0.0:PORT" to expose.
  int max_receive_message_bytes = 16 << 20;  // larger requests get RESOURCE_EXHAUSTED.
  int max_send_message_bytes = 16 << 20;
  int max_concurrent_estimates = 2;  // Estimate calls running at once; others wait.
  // At start, the Estimate calls' estimators lent first, as many as the process may use cores
  // (at most max_concurrent_estimates), each estimate the synthetic frame of
  // SourceConfig::warm_up once, on their own threads, in the background: the first calls then
  // cost what later ones do. Calls that come meanwhile wait for those slots or take a cold one.
  bool warm_up = true;
  // Admission control: Estimate calls held at once (running plus waiting for an estimator) and
  // the request bytes they may hold together; beyond either, RESOURCE_EXHAUSTED at once.
  int max_inflight_estimates = 4;
  std::int64_t max_inflight_request_bytes = std::int64_t{64} << 20;
  // Concurrent calls (streams) one client connection may open; more wait on the client side.
  int max_streams_per_client = 16;
  // StreamPoses calls one client may hold open at once; more are refused RESOURCE_EXHAUSTED.
  // A client is its bearer token when tokens are checked, else its network address (every
  // connection from one host counts together).
  int max_pose_streams_per_client = 16;
};

// The live web view, /metrics and /healthz (plain HTTP, read only).
struct HttpConfig {
  // "" = off. Loopback by default when given without a host; a non-loopback address needs
  // auth.insecure (the view has no TLS or tokens).
  std::string listen;
  int max_event_clients = 8;  // pages following /events at once; more get HTTP 503.
};

// Transport security and who may call. A daemon on a non-loopback address needs TLS (or an
// explicit `insecure`), so that poses and tokens never cross a network in the clear by accident.
struct SecurityConfig {
  std::string tls_cert;       // PEM server certificate (chain); "" = plaintext.
  std::string tls_key;        // PEM private key of tls_cert.
  std::string tls_client_ca;  // PEM CA bundle; given = mutual TLS, clients must present a cert.
  std::string tokens_file;    // bearer tokens with roles (TokenAuthorizer); "" = no tokens.
  bool insecure = false;      // allow a non-loopback address without TLS.

  bool tls() const { return !tls_cert.empty(); }
};

// The daemon's own frame source.
struct SourceConfig {
  std::string path;      // "" = none (Estimate calls only); see MakeFrameSource for the forms.
  bool realtime = true;  // recordings: true = recorded rate, false = as fast as possible.
  bool loop = false;     // recordings: start over at the end.
  double fps = 30.0;     // frame files whose names record no time, Hz.
  // The depth camera's intrinsics (intrinsics.json or ROS camera_info YAML) for every depth
  // frame, e.g. a calibrated Kinect on openni2://; "" = what the source knows.
  std::string intrinsics;
  // Frames waiting for the estimator; a live source drops the oldest. 1 keeps the latency
  // lowest: the estimator always takes the newest frame.
  int queue_capacity = 1;
  // Frames estimated at the same time, each by its own estimator on its own thread. 2 keeps up
  // with a source whose frames take up to two frame periods to estimate (on >= 2 cores);
  // poses are still published in frame order (a live source's late older frame is dropped).
  int estimate_threads = 1;
  // Track the robot over the stream: each frame's search starts from the previous frame's pose
  // (the result is the same, the global optimum is still proved) and the floor is kept while
  // it still fits the points (floor.mode fit) instead of being fitted every frame.
  bool tracking = true;
  // Before the source is opened, each estimation thread estimates one synthetic Kinect frame (a
  // humanoid on a floor among clutter, rendered at start) and drops the result: the buffers a
  // frame needs, its threads' scratch and the page faults of their first use are then paid
  // before the stream, not in its first frames. Nothing of it is published or followed.
  bool warm_up = true;
  // Where the robot stands when the stream starts (ground frame; source.initial_pose: {x_m,
  // y_m, theta_deg}): until it is first found, and again when the source restarts, frames are
  // searched as if the one before had seen it there (PoseTracker::SetInitialPose), so a robot
  // too far to pass search.score_threshold cold is found by search.tracked_score_threshold.
  // Needs tracking.
  bool has_initial_pose = false;
  Pose2D initial_pose;
  double frame_timeout_s = 2.0;              // live device: no frame for this long = lost.
  double reconnect_initial_backoff_s = 0.5;  // first retry delay after a loss, doubled each try.
  double reconnect_max_backoff_s = 8.0;      // upper bound of the retry delay.
  // OpenNI2's drivers stay loaded between the retries (drivers that watch the bus find the
  // device when it is back), and are reloaded at a retry at most this often (for drivers that
  // look for devices only when loaded); see LiveDeviceOptions.
  double driver_reload_interval_s = 60.0;
  double stale_after_s = 1.0;  // the latest estimate is stale when older than this.
};

// Floor handling: fitted in every frame, or a fixed calibration.
struct FloorConfig {
  bool fixed = false;
  double height_m = 0.34;  // optical centre above the floor (fixed mode).
  double pitch_rad = 0.0;  // positive = looking down (fixed mode).
  double roll_rad = 0.0;   // (fixed mode).
};

// The stereo-marker estimator's source: a directory of left/right frame pairs in the
// StereoSequence layout (DIR/frames.csv or DIR/left + DIR/right, optional DIR/calibration.yaml).
struct StereoConfig {
  std::string source;  // "" = no stereo source.
  // OpenCV stereo calibration (YAML/XML). "" = SOURCE/calibration.{yaml,yml,xml}. Given without
  // a source, it still enables the EstimateStereo call.
  std::string calibration;
  std::string calibration_unit = "m";  // unit of T in the calibration file: "m" or "mm".
  std::string options;                 // estimator options file; "" = StereoMarkerOptions{}.
  bool realtime = true;                // true = at the sequence's timestamps; false = fast.
  bool loop = false;                   // start over at the end.
  double fps = 15.0;                   // sequences without frames.csv: pairs per second, Hz.
  double stale_after_s = 1.0;          // the latest stereo estimate is stale when older than this.

  bool enabled() const { return !source.empty() || !calibration.empty(); }
};

// Where the depth sensor's ground frame lies in the world (field) frame of the stereo
// landmarks: the ground frame's origin (the floor point below the depth sensor's optical
// centre) at (x_m, y_m) in the world frame, its +x axis (the optical axis projected on the
// floor) turned yaw_rad counter-clockwise from world +x. A point p in the ground frame is
// R(yaw) p + (x, y) in the world frame. When configured, depth-template poses are also
// reported in the world frame.
struct WorldFrameConfig {
  bool configured = false;
  double x_m = 0.0;
  double y_m = 0.0;
  double yaw_rad = 0.0;
};

// DefaultEstimatorOptions() with a frame's searches on every usable core (search.threads 0):
// on two cores that keeps the arrival-to-published latency within two frame periods.
// Inline: the CLI front end reads this default without linking the config parser.
inline EstimatorOptions DefaultDaemonEstimatorOptions() {
  EstimatorOptions o = DefaultEstimatorOptions();
  o.threads = 0;
  return o;
}

// Everything hposed runs with. Defaults in one place: the member initialisers and
// DefaultDaemonEstimatorOptions().
struct DaemonConfig {
  GrpcConfig grpc;
  HttpConfig http;
  SecurityConfig security;
  SourceConfig source;
  std::vector<std::string> templates;  // .bt files.
  FloorConfig floor;
  EstimatorOptions estimator = DefaultDaemonEstimatorOptions();
  StereoConfig stereo;
  WorldFrameConfig world_from_ground;
};

// Parses YAML text (keys documented in server/hposed.example.yaml). Unknown keys, wrong types
// and out-of-range values fail with kInvalidArgument naming `origin` and the key, e.g.
// "hposed.yaml: source.rate: expected 'recorded' or 'fast', got 'slow'". Relative template and
// source paths are resolved against `base_dir` (the config file's directory).
Result<DaemonConfig> ParseDaemonConfig(const std::string& yaml_text, const std::string& origin,
                                       const std::string& base_dir);

// True when a templates: entry names a shipped template ("standing": no directory, no .bt)
// rather than giving a path; programs look names up among the shipped templates.
inline bool IsTemplateName(const std::string& entry) {
  return !entry.empty() && entry.find('/') == std::string::npos &&
         !(entry.size() >= 3 && entry.compare(entry.size() - 3, 3, ".bt") == 0);
}

// True for 127.x.y.z, localhost and [::1] listen addresses (HOST:PORT).
bool IsLoopbackListen(const std::string& listen);

// Reads and parses a config file (kNotFound when missing).
Result<DaemonConfig> LoadDaemonConfig(const std::string& path);

// Checks the cross-field rules (ranges, at least one template, valid listen address) of a
// config built from a file and/or flags. Messages name the key.
Status ValidateDaemonConfig(const DaemonConfig& config);

// The part of ValidateDaemonConfig that estimating frames rests on (search, floor, the initial
// pose), for programs that estimate without serving (hpose replay): "ORIGIN: search.stride:
// must be in [1, 16], got 0".
Status ValidateEstimationConfig(const DaemonConfig& config, const std::string& origin = "config");

// The effective config as YAML that ParseDaemonConfig accepts again.
std::string DaemonConfigToYaml(const DaemonConfig& config);

// The depth estimator's options a config gives: `estimator`, with the fixed floor of `floor`
// when floor.mode is fixed.
EstimatorOptions EffectiveEstimatorOptions(const DaemonConfig& config);

// Scorer names used by the config: "reference" (OctoMap) and "fast".
Result<ScorerKind> ParseScorerName(const std::string& name);
const char* ScorerName(ScorerKind kind);

}  // namespace hpose::server

#endif  // HPOSE_SERVER_DAEMON_CONFIG_H_
