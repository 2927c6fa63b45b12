// hpose::client: a C++ client of the hpose daemon (hposed, gRPC service hpose.v1.PoseService).
//
//   find_package(hpose REQUIRED)
//   target_link_libraries(my_controller PRIVATE hpose::client)
//
//   hpose::client::ConnectOptions options;       // 127.0.0.1:50051, plaintext
//   std::unique_ptr<hpose::client::Client> client;
//   hpose::client::Status s = hpose::client::Client::Connect(options, &client);
//   hpose::client::PoseEstimate e;
//   if (s.ok()) s = client->Latest(&e);
//
// This header holds plain structs only: the generated gRPC/protobuf headers stay inside the
// library. Units are SI (metres, radians, seconds) and frames are those of the API (docs/API.md):
// depth-template poses are the robot frame in the ground frame (origin on the floor below the
// sensor, +x along the optical axis projected on the floor, +y left, theta counter-clockwise).
// A Client may be used from several threads at once.
#ifndef HPOSE_CLIENT_H_
#define HPOSE_CLIENT_H_

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace hpose::client {

// The outcome of a call. `code` is the gRPC status code (0 = OK, 4 = DEADLINE_EXCEEDED,
// 5 = NOT_FOUND, 14 = UNAVAILABLE, 16 = UNAUTHENTICATED, ...; see docs/API.md for what the
// daemon answers when), `message` the daemon's or the library's reason.
struct Status {
  int code = 0;
  std::string message;
  bool ok() const { return code == 0; }
};

// Where the daemon is and how to reach it (the same choices as `hpose query`).
struct ConnectOptions {
  std::string address = "127.0.0.1:50051";  // host:port (or any gRPC target).
  std::string tls_ca_file;    // PEM CA that signed the daemon's certificate: connect with TLS.
  std::string tls_cert_file;  // PEM client certificate for mutual TLS (with tls_key_file).
  std::string tls_key_file;   // PEM private key of tls_cert_file.
  std::string token;          // bearer token sent with every call; "" = none.
  std::string token_file;     // or: a file whose first line is the token.
  double connect_timeout_s = 10.0;  // Connect waits this long for the daemon (it may be starting).
  double call_timeout_s = 10.0;     // deadline of each unary call (<= 0: none).
};

enum class Estimator { kAny = 0, kDepthTemplate = 1, kStereoMarker = 2 };

// In which points PoseEstimate::template_margin is: score points, fit points (both templates
// were refined), or at least that many score points (the other template's search stopped that
// far behind).
enum class MarginKind { kScore = 0, kFit = 1, kScoreAtLeast = 2 };

struct Pose2D {
  double x_m = 0.0;
  double y_m = 0.0;
  double theta_rad = 0.0;  // counter-clockwise from +x, in (-pi, pi].
};

// One estimate of either estimator. Depth-template fields are set for kDepthTemplate estimates,
// stereo fields for kStereoMarker ones.
struct PoseEstimate {
  Estimator estimator = Estimator::kAny;
  std::uint64_t sequence = 0;  // the source's frame number (Estimate calls: a per-call counter).
  double source_time_s = 0.0;  // the frame's time on the source's clock.
  std::string source;          // the source's description, or "request".
  bool stale = false;          // older than the daemon's stale_after_s, or the source is lost.
  std::string stale_reason;
  std::string
      error_code;  // set when the frame could not be estimated (e.g. "failed_precondition").
  std::string error_message;
  double estimate_time_s = 0.0;  // estimator time for the frame.
  double latency_s = 0.0;        // frame arrival in the daemon to estimate published.
  double age_s = 0.0;            // publication to sending, at the daemon.
  std::uint64_t skipped = 0;     // estimates of a stream skipped before this one (slow reader).

  // Depth template.
  bool humanoid_found = false;  // the best match passes the daemon's thresholds.
  bool has_match = false;       // a cluster was matched (pose, score... below are valid).
  std::string template_name;    // the best-matching template.
  Pose2D pose;                  // robot frame in the ground frame.
  double score = 0.0;           // 0-100: share of the cluster's voxels the template covers.
  // Points ahead of the best other template, in the points template_margin_kind names.
  double template_margin = 0.0;
  MarginKind template_margin_kind = MarginKind::kScore;
  bool has_runner_up = false;  // a second-best pose (often the robot turned around).
  Pose2D runner_up_pose;
  double runner_up_margin = 0.0;  // score - runner-up score.
  int clusters = 0;               // clusters found above the floor.
  double floor_height_m = 0.0;    // the sensor's optical centre above the floor.
  double floor_pitch_rad = 0.0;   // positive when the optical axis looks down.

  // Robot pose in the world (field) frame: the stereo estimator's, or the depth pose mapped
  // through the daemon's world_from_ground when one is configured.
  bool has_world_pose = false;
  Pose2D world_pose;

  // Stereo markers: the ball, in the world frame.
  bool object_found = false;
  double object_x_m = 0.0;
  double object_y_m = 0.0;
  bool object_moving = false;
};

// A depth image in millimetres (0 = no reading), row-major, with its pinhole intrinsics.
struct DepthImage {
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  std::vector<std::uint16_t> depth_mm;            // width * height values.
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;  // pixels.
};

// A point cloud in the depth sensor's optical frame (x right, y down, z forward), metres.
struct PointCloud {
  std::vector<float> xyz;  // x0 y0 z0 x1 y1 z1 ...
};

// What the daemon reports about itself (a summary of GetStatus).
struct DaemonStatus {
  std::string version;
  double uptime_s = 0.0;
  std::string source;        // the configured source, "" when none.
  std::string source_state;  // "none", "starting", "running", "reconnecting", "finished".
  std::uint64_t frames_in = 0;
  std::uint64_t frames_estimated = 0;
  std::uint64_t frames_dropped = 0;
  std::uint32_t templates = 0;
  // The size and camera of the source's depth frames read last (width 0 before the first
  // frame, and for a source of point clouds, which point_clouds says).
  std::uint32_t frame_width = 0;
  std::uint32_t frame_height = 0;
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;  // pixels.
  bool point_clouds = false;
};

struct StreamOptions {
  Estimator estimator = Estimator::kAny;  // kAny: both estimators' estimates.
  std::uint32_t max_estimates = 0;        // stop after this many (0 = until the callback stops).
  // The stream's deadline, seconds (0 = none): a daemon that stops sending (machine hung,
  // network cut) does not always close the stream; with a deadline Stream then returns
  // DEADLINE_EXCEEDED (4) and the caller can reconnect.
  double timeout_s = 0.0;
};

class Client {
 public:
  // Connects to the daemon, waiting up to options.connect_timeout_s for it. Fails with
  // UNAVAILABLE (14) when it cannot be reached, INVALID_ARGUMENT (3) for unreadable TLS or token
  // files or a certificate without its key.
  static Status Connect(const ConnectOptions& options, std::unique_ptr<Client>* out);

  ~Client();
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;

  // The newest estimate of the daemon's source (kAny: the depth source when there is one).
  // UNAVAILABLE (14) while there is none yet (the message says so and names the source state).
  Status Latest(PoseEstimate* out, Estimator estimator = Estimator::kAny);

  // Calls on_estimate with each estimate as the daemon publishes it, until on_estimate returns
  // false, max_estimates were delivered, options.timeout_s passed or the daemon ends the stream.
  // Blocks meanwhile; returns OK when stopped by the callback or the count.
  Status Stream(const std::function<bool(const PoseEstimate&)>& on_estimate,
                const StreamOptions& options = {});

  // Estimates the pose in a frame sent with the call. `templates` restricts the match to these
  // loaded templates (names; empty = all).
  Status Estimate(const DepthImage& depth, PoseEstimate* out,
                  const std::vector<std::string>& templates = {});
  Status Estimate(const PointCloud& cloud, PoseEstimate* out,
                  const std::vector<std::string>& templates = {});

  Status GetStatus(DaemonStatus* out);
  // The loaded templates' names.
  Status ListTemplates(std::vector<std::string>* names);

 private:
  struct Impl;
  explicit Client(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// Reads the x, y, z fields of a PCD file (DATA ascii or binary, 4-byte float fields; NaN
// points are dropped), such as those `hpose simulate` and PCL write. The message of
// a failure names the file and what is wrong.
Status ReadPcd(const std::string& path, PointCloud* out);

}  // namespace hpose::client

#endif  // HPOSE_CLIENT_H_
