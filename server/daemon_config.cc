#include "server/daemon_config.h"

#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "core/common/clock_limits.h"
#include "core/common/closest_name.h"
#include "core/io/atomic_file.h"
#include "server/openni2_source.h"
#include "server/tcp_listener.h"

namespace hpose::server {

namespace {

namespace fs = std::filesystem;

// Reads one YAML mapping, remembering which keys were used so unknown ones are reported.
class MapReader {
 public:
  MapReader(const YAML::Node& node, std::string path, std::string origin)
      : node_(node), path_(std::move(path)), origin_(std::move(origin)) {}

  Status CheckIsMap() const {
    if (node_.IsMap() || node_.IsNull()) return Status::Ok();
    return Fail(path_.empty() ? "the document" : path_, "expected a mapping");
  }

  std::string Key(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

  YAML::Node Get(const std::string& key) {
    seen_.insert(key);
    const YAML::Node& map = node_;  // const access: never inserts the key.
    if (!map.IsMap()) return YAML::Node();
    const YAML::Node value = map[key];
    return value.IsDefined() ? value : YAML::Node();  // missing keys read as null.
  }

  template <typename T>
  Status Read(const std::string& key, T* out, const char* type_name) {
    const YAML::Node n = Get(key);
    if (!n.IsDefined() || n.IsNull()) return Status::Ok();
    if (!n.IsScalar()) return Fail(Key(key), std::string("expected ") + type_name);
    try {
      *out = n.as<T>();
    } catch (const YAML::Exception&) {
      return Fail(Key(key), std::string("expected ") + type_name + ", got '" + n.Scalar() + "'");
    }
    return Status::Ok();
  }

  Status ReadDouble(const std::string& key, double* out) {
    Status s = Read(key, out, "a number");
    if (s.ok() && !std::isfinite(*out)) return Fail(Key(key), "must be finite");
    return s;
  }

  Status CheckUnknown() const {
    if (!node_.IsMap()) return Status::Ok();
    for (const auto& kv : node_) {
      const std::string k = kv.first.as<std::string>();
      if (seen_.count(k) == 0) {
        return Fail(Key(k), "unknown key" + DidYouMean(k, {seen_.begin(), seen_.end()}));
      }
    }
    return Status::Ok();
  }

  Status Fail(const std::string& key, const std::string& what) const {
    return MakeError(ErrorCode::kInvalidArgument, origin_ + ": " + key + ": " + what);
  }

  // Reads the optional key "rate" ('recorded': replay at the recorded rate; 'fast': as fast
  // as possible); `realtime` is left as it was when the key is absent.
  Status ReadRate(bool* realtime) {
    std::string rate;
    Status st = Read("rate", &rate, "'recorded' or 'fast'");
    if (!st.ok()) return st;
    if (rate == "recorded") {
      *realtime = true;
    } else if (rate == "fast") {
      *realtime = false;
    } else if (!rate.empty()) {
      return Fail(Key("rate"), "expected 'recorded' or 'fast', got '" + rate + "'");
    }
    return Status::Ok();
  }

 private:
  YAML::Node node_;
  std::string path_;
  std::string origin_;
  std::set<std::string> seen_;
};

#define HPOSE_RETURN_IF_ERROR(expr)  \
  do {                               \
    Status _s = (expr);              \
    if (!_s.ok()) return _s.error(); \
  } while (false)

// A path of the config file made absolute against the file's directory, so that messages name
// the file actually meant and the config works from any working directory.
std::string Resolve(const std::string& base_dir, const std::string& path) {
  if (path.empty() || base_dir.empty() || IsOpenni2DeviceSpec(path)) return path;
  const fs::path p(path);
  if (p.is_absolute()) return path;
  std::error_code ec;
  fs::path base = fs::absolute(base_dir, ec);
  if (ec) base = base_dir;
  return (base / p).lexically_normal().string();
}

// A template entry: a shipped template's name ("standing": no directory, no .bt) stays a name
// for the program to look up among the shipped templates; a path is resolved.
std::string ResolveTemplate(const std::string& base_dir, const std::string& entry) {
  if (IsTemplateName(entry)) return entry;
  return Resolve(base_dir, entry);
}

Status ParseInto(const YAML::Node& root, const std::string& origin, const std::string& base_dir,
                 DaemonConfig* c) {
  MapReader top(root, "", origin);
  HPOSE_RETURN_IF_ERROR(top.CheckIsMap());
  HPOSE_RETURN_IF_ERROR(top.Read("listen", &c->grpc.listen, "a host:port string"));

  {
    MapReader r(top.Get("grpc"), "grpc", origin);
    HPOSE_RETURN_IF_ERROR(r.CheckIsMap());
    HPOSE_RETURN_IF_ERROR(
        r.Read("max_receive_message_bytes", &c->grpc.max_receive_message_bytes, "an integer"));
    HPOSE_RETURN_IF_ERROR(
        r.Read("max_send_message_bytes", &c->grpc.max_send_message_bytes, "an integer"));
    HPOSE_RETURN_IF_ERROR(
        r.Read("max_concurrent_estimates", &c->grpc.max_concurrent_estimates, "an integer"));
    HPOSE_RETURN_IF_ERROR(r.Read("warm_up", &c->grpc.warm_up, "true or false"));
    HPOSE_RETURN_IF_ERROR(
        r.Read("max_inflight_estimates", &c->grpc.max_inflight_estimates, "an integer"));
    HPOSE_RETURN_IF_ERROR(
        r.Read("max_inflight_request_bytes", &c->grpc.max_inflight_request_bytes, "an integer"));
    HPOSE_RETURN_IF_ERROR(
        r.Read("max_streams_per_client", &c->grpc.max_streams_per_client, "an integer"));
    HPOSE_RETURN_IF_ERROR(
        r.Read("max_pose_streams_per_client", &c->grpc.max_pose_streams_per_client, "an integer"));
    HPOSE_RETURN_IF_ERROR(r.CheckUnknown());
  }
  {
    MapReader r(top.Get("http"), "http", origin);
    HPOSE_RETURN_IF_ERROR(r.CheckIsMap());
    HPOSE_RETURN_IF_ERROR(r.Read("listen", &c->http.listen, "a host:port string"));
    HPOSE_RETURN_IF_ERROR(r.Read("max_event_clients", &c->http.max_event_clients, "an integer"));
    HPOSE_RETURN_IF_ERROR(r.CheckUnknown());
  }
  {
    MapReader r(top.Get("tls"), "tls", origin);
    HPOSE_RETURN_IF_ERROR(r.CheckIsMap());
    SecurityConfig& s = c->security;
    HPOSE_RETURN_IF_ERROR(r.Read("cert", &s.tls_cert, "a PEM file"));
    HPOSE_RETURN_IF_ERROR(r.Read("key", &s.tls_key, "a PEM file"));
    HPOSE_RETURN_IF_ERROR(r.Read("client_ca", &s.tls_client_ca, "a PEM file"));
    HPOSE_RETURN_IF_ERROR(r.CheckUnknown());
    s.tls_cert = Resolve(base_dir, s.tls_cert);
    s.tls_key = Resolve(base_dir, s.tls_key);
    s.tls_client_ca = Resolve(base_dir, s.tls_client_ca);
  }
  {
    MapReader r(top.Get("auth"), "auth", origin);
    HPOSE_RETURN_IF_ERROR(r.CheckIsMap());
    HPOSE_RETURN_IF_ERROR(r.Read("tokens_file", &c->security.tokens_file, "a path"));
    HPOSE_RETURN_IF_ERROR(r.Read("insecure", &c->security.insecure, "true or false"));
    HPOSE_RETURN_IF_ERROR(r.CheckUnknown());
    c->security.tokens_file = Resolve(base_dir, c->security.tokens_file);
  }
  {
    MapReader r(top.Get("source"), "source", origin);
    HPOSE_RETURN_IF_ERROR(r.CheckIsMap());
    SourceConfig& s = c->source;
    HPOSE_RETURN_IF_ERROR(r.Read("path", &s.path, "a path"));
    s.path = Resolve(base_dir, s.path);
    HPOSE_RETURN_IF_ERROR(r.ReadRate(&s.realtime));
    HPOSE_RETURN_IF_ERROR(r.Read("loop", &s.loop, "true or false"));
    HPOSE_RETURN_IF_ERROR(r.ReadDouble("fps", &s.fps));
    HPOSE_RETURN_IF_ERROR(r.Read("intrinsics", &s.intrinsics, "a path"));
    s.intrinsics = Resolve(base_dir, s.intrinsics);
    HPOSE_RETURN_IF_ERROR(r.Read("queue_capacity", &s.queue_capacity, "an integer"));
    HPOSE_RETURN_IF_ERROR(r.Read("estimate_threads", &s.estimate_threads, "an integer"));
    HPOSE_RETURN_IF_ERROR(r.Read("tracking", &s.tracking, "true or false"));
    HPOSE_RETURN_IF_ERROR(r.Read("warm_up", &s.warm_up, "true or false"));
    const YAML::Node initial = r.Get("initial_pose");
    if (initial.IsDefined() && !initial.IsNull()) {
      MapReader p(initial, "source.initial_pose", origin);
      HPOSE_RETURN_IF_ERROR(p.CheckIsMap());
      for (const char* required : {"x_m", "y_m"}) {
        const YAML::Node n = p.Get(required);
        if (!n.IsDefined() || n.IsNull()) {
          return p.Fail("source.initial_pose", "x_m and y_m are required (theta_deg: 0 if absent)");
        }
      }
      double x = 0.0, y = 0.0, theta_deg = 0.0;
      HPOSE_RETURN_IF_ERROR(p.ReadDouble("x_m", &x));
      HPOSE_RETURN_IF_ERROR(p.ReadDouble("y_m", &y));
      HPOSE_RETURN_IF_ERROR(p.ReadDouble("theta_deg", &theta_deg));
      HPOSE_RETURN_IF_ERROR(p.CheckUnknown());
      s.has_initial_pose = true;
      s.initial_pose = Pose2D{x, y, NormalizeAngle(DegToRad(theta_deg))};
    }
    HPOSE_RETURN_IF_ERROR(r.ReadDouble("frame_timeout_s", &s.frame_timeout_s));
    HPOSE_RETURN_IF_ERROR(
        r.ReadDouble("reconnect_initial_backoff_s", &s.reconnect_initial_backoff_s));
    HPOSE_RETURN_IF_ERROR(r.ReadDouble("reconnect_max_backoff_s", &s.reconnect_max_backoff_s));
    HPOSE_RETURN_IF_ERROR(r.ReadDouble("driver_reload_interval_s", &s.driver_reload_interval_s));
    HPOSE_RETURN_IF_ERROR(r.ReadDouble("stale_after_s", &s.stale_after_s));
    HPOSE_RETURN_IF_ERROR(r.CheckUnknown());
  }
  {
    const YAML::Node t = top.Get("templates");
    if (t.IsDefined() && !t.IsNull()) {
      if (!t.IsSequence()) return top.Fail("templates", "expected a list of .bt files");
      c->templates.clear();
      for (size_t i = 0; i < t.size(); ++i) {
        if (!t[i].IsScalar()) {
          return top.Fail("templates[" + std::to_string(i) + "]", "expected a path");
        }
        c->templates.push_back(ResolveTemplate(base_dir, t[i].Scalar()));
      }
    }
  }
  {
    MapReader r(top.Get("search"), "search", origin);
    HPOSE_RETURN_IF_ERROR(r.CheckIsMap());
    EstimatorOptions& e = c->estimator;
    std::string kind, scorer;
    HPOSE_RETURN_IF_ERROR(r.Read("kind", &kind, "'paper' or 'exact'"));
    if (!kind.empty()) {
      Result<SearchKind> k = ParseSearchKind(kind);
      if (!k.ok()) return r.Fail("search.kind", "expected 'paper' or 'exact', got '" + kind + "'");
      e.search = *k;
    }
    HPOSE_RETURN_IF_ERROR(r.Read("scorer", &scorer, "'reference' or 'fast'"));
    if (!scorer.empty()) {
      Result<ScorerKind> k = ParseScorerName(scorer);
      if (!k.ok()) {
        return r.Fail("search.scorer", "expected 'reference' or 'fast', got '" + scorer + "'");
      }
      e.scorer = *k;
    }
    HPOSE_RETURN_IF_ERROR(r.ReadDouble("score_threshold", &e.score_threshold));
    HPOSE_RETURN_IF_ERROR(r.ReadDouble("min_humanoid_fit", &e.min_humanoid_fit));
    HPOSE_RETURN_IF_ERROR(r.ReadDouble("min_humanoid_evidence", &e.min_humanoid_evidence));
    HPOSE_RETURN_IF_ERROR(r.ReadDouble("tracked_hold_min_evidence", &e.tracked_hold_min_evidence));
    HPOSE_RETURN_IF_ERROR(r.ReadDouble("tracked_score_threshold", &e.tracked_score_threshold));
    HPOSE_RETURN_IF_ERROR(r.ReadDouble("far_range_m", &e.far_range_m));
    HPOSE_RETURN_IF_ERROR(
        r.ReadDouble("two_points_a_voxel_within_m", &e.two_points_a_voxel_within_m));
    HPOSE_RETURN_IF_ERROR(r.ReadDouble("far_score_ratio", &e.far_score_ratio));
    HPOSE_RETURN_IF_ERROR(r.ReadDouble("far_min_evidence", &e.far_min_evidence));
    HPOSE_RETURN_IF_ERROR(r.ReadDouble("max_height_ratio_error", &e.max_height_ratio_error));
    HPOSE_RETURN_IF_ERROR(r.Read("height_offset_voxels", &e.height_offset_voxels, "an integer"));
    HPOSE_RETURN_IF_ERROR(
        r.ReadDouble("height_offset_min_coverage", &e.height_offset_min_coverage));
    // 0: the templates' own edge (coarser for a tall body), EstimatorOptions::
    // resolution_from_templates.
    double resolution_m = e.resolution_from_templates ? 0.0 : e.lattice.resolution_m;
    HPOSE_RETURN_IF_ERROR(r.ReadDouble("resolution_m", &resolution_m));
    e.resolution_from_templates = resolution_m == 0.0;
    if (!e.resolution_from_templates) e.lattice.resolution_m = resolution_m;
    HPOSE_RETURN_IF_ERROR(r.Read("max_height_voxels", &e.max_height_voxels, "an integer"));
    HPOSE_RETURN_IF_ERROR(r.ReadDouble("min_range_m", &e.cloud.min_range_m));
    HPOSE_RETURN_IF_ERROR(r.ReadDouble("max_range_m", &e.cloud.max_range_m));
    HPOSE_RETURN_IF_ERROR(r.Read("stride", &e.cloud.stride, "an integer"));
    HPOSE_RETURN_IF_ERROR(r.Read("threads", &e.threads, "an integer"));
    HPOSE_RETURN_IF_ERROR(r.CheckUnknown());
  }
  {
    MapReader r(top.Get("floor"), "floor", origin);
    HPOSE_RETURN_IF_ERROR(r.CheckIsMap());
    FloorConfig& f = c->floor;
    std::string mode;
    HPOSE_RETURN_IF_ERROR(r.Read("mode", &mode, "'fit' or 'fixed'"));
    if (mode == "fit") {
      f.fixed = false;
    } else if (mode == "fixed") {
      f.fixed = true;
    } else if (!mode.empty()) {
      return r.Fail("floor.mode", "expected 'fit' or 'fixed', got '" + mode + "'");
    }
    HPOSE_RETURN_IF_ERROR(r.ReadDouble("height_m", &f.height_m));
    HPOSE_RETURN_IF_ERROR(r.ReadDouble("pitch_rad", &f.pitch_rad));
    HPOSE_RETURN_IF_ERROR(r.ReadDouble("roll_rad", &f.roll_rad));
    HPOSE_RETURN_IF_ERROR(
        r.ReadDouble("distance_threshold_m", &c->estimator.floor_fit.distance_threshold_m));
    HPOSE_RETURN_IF_ERROR(r.ReadDouble("min_width_m", &c->estimator.floor_fit.min_width_m));
    HPOSE_RETURN_IF_ERROR(r.ReadDouble("max_tilt_rad", &c->estimator.floor_fit.max_tilt_rad));
    HPOSE_RETURN_IF_ERROR(r.CheckUnknown());
  }
  {
    MapReader r(top.Get("stereo"), "stereo", origin);
    HPOSE_RETURN_IF_ERROR(r.CheckIsMap());
    StereoConfig& s = c->stereo;
    HPOSE_RETURN_IF_ERROR(r.Read("source", &s.source, "a directory"));
    s.source = Resolve(base_dir, s.source);
    HPOSE_RETURN_IF_ERROR(r.Read("calibration", &s.calibration, "a path"));
    s.calibration = Resolve(base_dir, s.calibration);
    HPOSE_RETURN_IF_ERROR(r.Read("calibration_unit", &s.calibration_unit, "'m' or 'mm'"));
    HPOSE_RETURN_IF_ERROR(r.Read("options", &s.options, "a path"));
    s.options = Resolve(base_dir, s.options);
    HPOSE_RETURN_IF_ERROR(r.ReadRate(&s.realtime));
    HPOSE_RETURN_IF_ERROR(r.Read("loop", &s.loop, "true or false"));
    HPOSE_RETURN_IF_ERROR(r.ReadDouble("fps", &s.fps));
    HPOSE_RETURN_IF_ERROR(r.ReadDouble("stale_after_s", &s.stale_after_s));
    HPOSE_RETURN_IF_ERROR(r.CheckUnknown());
  }
  {
    const YAML::Node w = top.Get("world_from_ground");
    if (w.IsDefined() && !w.IsNull()) {
      MapReader r(w, "world_from_ground", origin);
      HPOSE_RETURN_IF_ERROR(r.CheckIsMap());
      WorldFrameConfig& f = c->world_from_ground;
      f.configured = true;
      HPOSE_RETURN_IF_ERROR(r.ReadDouble("x_m", &f.x_m));
      HPOSE_RETURN_IF_ERROR(r.ReadDouble("y_m", &f.y_m));
      HPOSE_RETURN_IF_ERROR(r.ReadDouble("yaw_rad", &f.yaw_rad));
      HPOSE_RETURN_IF_ERROR(r.CheckUnknown());
    }
  }
  HPOSE_RETURN_IF_ERROR(top.CheckUnknown());
  return Status::Ok();
}

bool ValidListen(const std::string& listen) { return ParseHostPort(listen).ok(); }

}  // namespace

bool IsLoopbackListen(const std::string& listen) {
  Result<HostPort> address = ParseHostPort(listen);
  if (!address.ok()) return false;
  const std::string& host = address->host;
  return host == "localhost" || host == "::1" || host.rfind("127.", 0) == 0;
}

Result<ScorerKind> ParseScorerName(const std::string& name) {
  if (name == "reference") return ScorerKind::kOctomapReference;
  if (name == "fast") return ScorerKind::kFast;
  return MakeError(ErrorCode::kInvalidArgument,
                   "unknown scorer '" + name + "' (expected 'reference' or 'fast')");
}

const char* ScorerName(ScorerKind kind) { return kind == ScorerKind::kFast ? "fast" : "reference"; }

Result<DaemonConfig> ParseDaemonConfig(const std::string& yaml_text, const std::string& origin,
                                       const std::string& base_dir) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    return MakeError(
        ErrorCode::kInvalidArgument,
        origin + ": not valid YAML: line " + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  DaemonConfig config;
  try {
    Status s = ParseInto(root, origin, base_dir, &config);
    if (!s.ok()) return s.error();
  } catch (const YAML::Exception& e) {
    return MakeError(ErrorCode::kInvalidArgument, origin + ": " + e.msg);
  }
  return config;
}

Result<DaemonConfig> LoadDaemonConfig(const std::string& path) {
  Result<std::string> text = ReadFile(path);
  if (!text.ok()) return text.error();
  const std::string base = fs::path(path).parent_path().string();
  return ParseDaemonConfig(*text, path, base.empty() ? "." : base);
}

Status ValidateEstimationConfig(const DaemonConfig& c, const std::string& origin) {
  auto fail = [&origin](const std::string& key, const std::string& what) {
    return Status(MakeError(ErrorCode::kInvalidArgument, origin + ": " + key + ": " + what));
  };
  if (c.estimator.threads < 0 || c.estimator.threads > 256) {
    return fail("search.threads", "must be in [0, 256] (0: one per core)");
  }
  if (!(c.estimator.score_threshold >= 0.0 && c.estimator.score_threshold <= 100.0)) {
    return fail("search.score_threshold", "must be in [0, 100]");
  }
  if (!(c.estimator.min_humanoid_fit >= 0.0 && c.estimator.min_humanoid_fit <= 100.0)) {
    return fail("search.min_humanoid_fit", "must be in [0, 100]");
  }
  if (!(c.estimator.min_humanoid_evidence >= 0.0 && c.estimator.min_humanoid_evidence <= 1.0)) {
    return fail("search.min_humanoid_evidence", "must be in [0, 1]");
  }
  if (!(c.estimator.tracked_hold_min_evidence >= 0.0 &&
        c.estimator.tracked_hold_min_evidence <= 1.0)) {
    return fail("search.tracked_hold_min_evidence", "must be in [0, 1]");
  }
  if (c.source.has_initial_pose) {
    const Pose2D& p = c.source.initial_pose;
    if (!(std::abs(p.x) <= 100.0 && std::abs(p.y) <= 100.0 && std::isfinite(p.theta))) {
      return fail("source.initial_pose", "x_m and y_m must be within +-100 m");
    }
    if (!c.source.tracking) {
      return fail("source.initial_pose", "needs source.tracking: true (it seeds the tracking)");
    }
  }
  if (!(c.estimator.tracked_score_threshold >= 0.0 &&
        c.estimator.tracked_score_threshold <= 100.0)) {
    return fail("search.tracked_score_threshold", "must be in [0, 100]");
  }
  if (!(c.estimator.two_points_a_voxel_within_m >= 0.0)) {
    return fail("search.two_points_a_voxel_within_m", "must be at least 0 metres (0: off)");
  }
  if (!(c.estimator.far_range_m >= 0.0)) {
    return fail("search.far_range_m", "must be at least 0 metres (.inf: no far clusters)");
  }
  if (!(c.estimator.far_score_ratio >= 0.0 && c.estimator.far_score_ratio <= 1.0)) {
    return fail("search.far_score_ratio", "must be in [0, 1] (1: one threshold at every range)");
  }
  if (!(c.estimator.far_min_evidence >= 0.0 && c.estimator.far_min_evidence <= 1.0)) {
    return fail("search.far_min_evidence", "must be in [0, 1]");
  }
  if (!c.floor.fixed) {
    const FloorFitterOptions& fit = c.estimator.floor_fit;
    if (!(fit.distance_threshold_m > 0.0 && fit.distance_threshold_m <= 1.0)) {
      return fail("floor.distance_threshold_m", "must be in (0, 1] metres");
    }
    if (!(fit.min_width_m >= 0.0 && fit.min_width_m < 100.0)) {
      return fail("floor.min_width_m", "must be in [0, 100) metres (0: no width check)");
    }
    // As a fixed floor's pitch: within 1.5 rad (85.9 degrees), short of looking straight down.
    if (!(fit.max_tilt_rad > 0.0 && fit.max_tilt_rad <= 1.5)) {
      return fail("floor.max_tilt_rad", "must be in (0, 1.5] rad (1.22: 70 degrees)");
    }
  } else {
    if (!(c.floor.height_m > 0.0 && c.floor.height_m < 10.0)) {
      return fail("floor.height_m", "must be in (0, 10) metres");
    }
    if (!(std::fabs(c.floor.pitch_rad) < 1.5 && std::fabs(c.floor.roll_rad) < 1.5)) {
      return fail("floor.pitch_rad", "pitch and roll must be within +-1.5 rad");
    }
  }
  const DepthToCloudOptions& cloud = c.estimator.cloud;
  if (cloud.stride < 1 || cloud.stride > 16) {
    return fail("search.stride", "must be in [1, 16], got " + std::to_string(cloud.stride));
  }
  if (!(cloud.min_range_m >= 0.0 && cloud.max_range_m > cloud.min_range_m &&
        cloud.max_range_m <= 100.0)) {
    return fail("search.max_range_m",
                "the readings kept must lie within 0 <= min_range_m < max_range_m <= 100 metres");
  }
  Status lattice = c.estimator.lattice.Validate();
  if (!c.estimator.resolution_from_templates && !lattice.ok()) {
    return fail("search.resolution_m", lattice.error().message + " (0: the templates' own)");
  }
  const int tall = c.estimator.max_height_voxels;
  if (tall != 0 && (tall < 8 || tall > 1024)) {
    return fail("search.max_height_voxels", "must be 0 (off) or within [8, 1024]");
  }
  const int offsets = c.estimator.height_offset_voxels;
  if (offsets < 0 || offsets > 8) {
    return fail("search.height_offset_voxels", "must be within [0, 8]");
  }
  const double coverage = c.estimator.height_offset_min_coverage;
  if (!(coverage >= 0.0 && coverage <= 1.0)) {
    return fail("search.height_offset_min_coverage", "must be in [0, 1]");
  }
  return Status::Ok();
}

Status ValidateDaemonConfig(const DaemonConfig& c) {
  auto fail = [](const std::string& key, const std::string& what) {
    return Status(MakeError(ErrorCode::kInvalidArgument, "config: " + key + ": " + what));
  };
  if (!ValidListen(c.grpc.listen)) {
    return fail("listen", "expected HOST:PORT (e.g. 127.0.0.1:50051), got '" + c.grpc.listen + "'");
  }
  const SecurityConfig& sec = c.security;
  if (sec.tls_cert.empty() != sec.tls_key.empty()) {
    return fail("tls", "cert and key go together");
  }
  if (!sec.tls_client_ca.empty() && !sec.tls()) {
    return fail("tls.client_ca", "mutual TLS needs the server's cert and key too");
  }
  if (!sec.tls() && !sec.insecure && !IsLoopbackListen(c.grpc.listen)) {
    return fail("listen", "refusing to serve " + c.grpc.listen +
                              " without TLS: anyone on the network could read poses and send "
                              "requests. Configure tls: {cert, key} (and auth: tokens_file), or "
                              "pass --insecure to accept that on a trusted network");
  }
  if (!c.http.listen.empty()) {
    if (!ValidListen(c.http.listen)) {
      return fail("http.listen",
                  "expected HOST:PORT (e.g. 127.0.0.1:8080), got '" + c.http.listen + "'");
    }
    if (!sec.insecure && !IsLoopbackListen(c.http.listen)) {
      return fail("http.listen", "refusing to serve the web view on " + c.http.listen +
                                     ": it has no TLS or tokens, anyone on the network could "
                                     "watch; pass --insecure to accept that on a trusted network");
    }
  }
  if (c.http.max_event_clients < 1 || c.http.max_event_clients > 64) {
    return fail("http.max_event_clients", "must be in [1, 64]");
  }
  if (c.grpc.max_receive_message_bytes < 1024 || c.grpc.max_send_message_bytes < 1024) {
    return fail("grpc.max_receive_message_bytes", "message limits must be at least 1024 bytes");
  }
  if (c.grpc.max_concurrent_estimates < 1 || c.grpc.max_concurrent_estimates > 64) {
    return fail("grpc.max_concurrent_estimates", "must be in [1, 64]");
  }
  if (c.grpc.max_inflight_estimates < c.grpc.max_concurrent_estimates ||
      c.grpc.max_inflight_estimates > 1024) {
    return fail("grpc.max_inflight_estimates", "must be in [max_concurrent_estimates, 1024]");
  }
  if (c.grpc.max_inflight_request_bytes < c.grpc.max_receive_message_bytes) {
    return fail("grpc.max_inflight_request_bytes",
                "must be at least max_receive_message_bytes (one largest request)");
  }
  if (c.grpc.max_streams_per_client < 1 || c.grpc.max_streams_per_client > 10000) {
    return fail("grpc.max_streams_per_client", "must be in [1, 10000]");
  }
  if (c.grpc.max_pose_streams_per_client < 1 || c.grpc.max_pose_streams_per_client > 10000) {
    return fail("grpc.max_pose_streams_per_client", "must be in [1, 10000]");
  }
  const SourceConfig& s = c.source;
  // Rates and durations stay where a clock can count them (core/common/clock_limits.h).
  const auto rate_ok = FrameRateInRange;
  const auto wait_ok = WaitInRange;
  if (!rate_ok(s.fps)) return fail("source.fps", "must be in [0.01, 10000] frames a second");
  if (s.queue_capacity < 1 || s.queue_capacity > 1000) {
    return fail("source.queue_capacity", "must be in [1, 1000]");
  }
  if (s.estimate_threads < 1 || s.estimate_threads > 64) {
    return fail("source.estimate_threads", "must be in [1, 64]");
  }
  if (!wait_ok(s.frame_timeout_s)) {
    return fail("source.frame_timeout_s", "must be in (0, 86400] seconds");
  }
  if (!wait_ok(s.reconnect_initial_backoff_s)) {
    return fail("source.reconnect_initial_backoff_s", "must be in (0, 86400] seconds");
  }
  if (!(wait_ok(s.reconnect_max_backoff_s) &&
        s.reconnect_max_backoff_s >= s.reconnect_initial_backoff_s)) {
    return fail("source.reconnect_max_backoff_s",
                "must be >= reconnect_initial_backoff_s and at most 86400 seconds");
  }
  if (!wait_ok(s.stale_after_s)) {
    return fail("source.stale_after_s", "must be in (0, 86400] seconds");
  }
  if (!(s.driver_reload_interval_s >= 0.0 && s.driver_reload_interval_s <= 86400.0)) {
    return fail("source.driver_reload_interval_s", "must be in [0, 86400] seconds");
  }
  if (c.templates.empty()) {
    return fail("templates",
                "no template given (use --template FILE.bt or templates: in the config)");
  }
  for (const std::string& t : c.templates) {
    if (t.size() < 4 || t.compare(t.size() - 3, 3, ".bt") != 0) {
      return fail("templates", "'" + t + "' is neither a .bt file nor a shipped template's name");
    }
  }
  HPOSE_RETURN_IF_ERROR(ValidateEstimationConfig(c));
  const StereoConfig& st = c.stereo;
  if (st.calibration_unit != "m" && st.calibration_unit != "mm") {
    return fail("stereo.calibration_unit",
                "expected 'm' or 'mm', got '" + st.calibration_unit + "'");
  }
  if (!rate_ok(st.fps)) return fail("stereo.fps", "must be in [0.01, 10000] frames a second");
  if (!wait_ok(st.stale_after_s)) {
    return fail("stereo.stale_after_s", "must be in (0, 86400] seconds");
  }
  const WorldFrameConfig& w = c.world_from_ground;
  if (w.configured && !(std::abs(w.x_m) <= 1e4 && std::abs(w.y_m) <= 1e4 &&
                        std::abs(w.yaw_rad) <= 1e3)) {  // NaN fails too.
    return fail("world_from_ground",
                "x_m and y_m must be within 10000 m and yaw_rad within 1000 rad (finite)");
  }
  return Status::Ok();
}

std::string DaemonConfigToYaml(const DaemonConfig& c) {
  YAML::Emitter out;
  out.SetDoublePrecision(12);
  out << YAML::BeginMap;
  out << YAML::Key << "listen" << YAML::Value << c.grpc.listen;
  out << YAML::Key << "grpc" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "max_receive_message_bytes" << YAML::Value
      << c.grpc.max_receive_message_bytes;
  out << YAML::Key << "max_send_message_bytes" << YAML::Value << c.grpc.max_send_message_bytes;
  out << YAML::Key << "max_concurrent_estimates" << YAML::Value << c.grpc.max_concurrent_estimates;
  out << YAML::Key << "warm_up" << YAML::Value << c.grpc.warm_up;
  out << YAML::Key << "max_inflight_estimates" << YAML::Value << c.grpc.max_inflight_estimates;
  out << YAML::Key << "max_inflight_request_bytes" << YAML::Value
      << c.grpc.max_inflight_request_bytes;
  out << YAML::Key << "max_streams_per_client" << YAML::Value << c.grpc.max_streams_per_client;
  out << YAML::Key << "max_pose_streams_per_client" << YAML::Value
      << c.grpc.max_pose_streams_per_client;
  out << YAML::EndMap;
  out << YAML::Key << "http" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "listen" << YAML::Value << c.http.listen;
  out << YAML::Key << "max_event_clients" << YAML::Value << c.http.max_event_clients;
  out << YAML::EndMap;
  out << YAML::Key << "tls" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "cert" << YAML::Value << c.security.tls_cert;
  out << YAML::Key << "key" << YAML::Value << c.security.tls_key;
  out << YAML::Key << "client_ca" << YAML::Value << c.security.tls_client_ca;
  out << YAML::EndMap;
  out << YAML::Key << "auth" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "tokens_file" << YAML::Value << c.security.tokens_file;
  out << YAML::Key << "insecure" << YAML::Value << c.security.insecure;
  out << YAML::EndMap;
  const SourceConfig& s = c.source;
  out << YAML::Key << "source" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "path" << YAML::Value << s.path;
  out << YAML::Key << "rate" << YAML::Value << (s.realtime ? "recorded" : "fast");
  out << YAML::Key << "loop" << YAML::Value << s.loop;
  out << YAML::Key << "fps" << YAML::Value << s.fps;
  out << YAML::Key << "intrinsics" << YAML::Value << s.intrinsics;
  out << YAML::Key << "queue_capacity" << YAML::Value << s.queue_capacity;
  out << YAML::Key << "estimate_threads" << YAML::Value << s.estimate_threads;
  out << YAML::Key << "tracking" << YAML::Value << s.tracking;
  out << YAML::Key << "warm_up" << YAML::Value << s.warm_up;
  if (s.has_initial_pose) {
    out << YAML::Key << "initial_pose" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "x_m" << YAML::Value << s.initial_pose.x;
    out << YAML::Key << "y_m" << YAML::Value << s.initial_pose.y;
    out << YAML::Key << "theta_deg" << YAML::Value << RadToDeg(s.initial_pose.theta);
    out << YAML::EndMap;
  }
  out << YAML::Key << "frame_timeout_s" << YAML::Value << s.frame_timeout_s;
  out << YAML::Key << "reconnect_initial_backoff_s" << YAML::Value << s.reconnect_initial_backoff_s;
  out << YAML::Key << "reconnect_max_backoff_s" << YAML::Value << s.reconnect_max_backoff_s;
  out << YAML::Key << "driver_reload_interval_s" << YAML::Value << s.driver_reload_interval_s;
  out << YAML::Key << "stale_after_s" << YAML::Value << s.stale_after_s;
  out << YAML::EndMap;
  out << YAML::Key << "templates" << YAML::Value << YAML::BeginSeq;
  for (const std::string& t : c.templates) out << t;
  out << YAML::EndSeq;
  const EstimatorOptions& e = c.estimator;
  out << YAML::Key << "search" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "kind" << YAML::Value << SearchKindName(e.search);
  out << YAML::Key << "scorer" << YAML::Value << ScorerName(e.scorer);
  out << YAML::Key << "score_threshold" << YAML::Value << e.score_threshold;
  out << YAML::Key << "min_humanoid_fit" << YAML::Value << e.min_humanoid_fit;
  out << YAML::Key << "min_humanoid_evidence" << YAML::Value << e.min_humanoid_evidence;
  out << YAML::Key << "tracked_hold_min_evidence" << YAML::Value << e.tracked_hold_min_evidence;
  out << YAML::Key << "tracked_score_threshold" << YAML::Value << e.tracked_score_threshold;
  out << YAML::Key << "far_range_m" << YAML::Value << e.far_range_m;
  out << YAML::Key << "two_points_a_voxel_within_m" << YAML::Value << e.two_points_a_voxel_within_m;
  out << YAML::Key << "far_score_ratio" << YAML::Value << e.far_score_ratio;
  out << YAML::Key << "far_min_evidence" << YAML::Value << e.far_min_evidence;
  out << YAML::Key << "max_height_ratio_error" << YAML::Value << e.max_height_ratio_error;
  out << YAML::Key << "height_offset_voxels" << YAML::Value << e.height_offset_voxels;
  out << YAML::Key << "height_offset_min_coverage" << YAML::Value << e.height_offset_min_coverage;
  out << YAML::Key << "resolution_m" << YAML::Value
      << (e.resolution_from_templates ? 0.0 : e.lattice.resolution_m);
  out << YAML::Key << "max_height_voxels" << YAML::Value << e.max_height_voxels;
  out << YAML::Key << "min_range_m" << YAML::Value << e.cloud.min_range_m;
  out << YAML::Key << "max_range_m" << YAML::Value << e.cloud.max_range_m;
  out << YAML::Key << "stride" << YAML::Value << e.cloud.stride;
  out << YAML::Key << "threads" << YAML::Value << e.threads;
  out << YAML::EndMap;
  out << YAML::Key << "floor" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "mode" << YAML::Value << (c.floor.fixed ? "fixed" : "fit");
  out << YAML::Key << "height_m" << YAML::Value << c.floor.height_m;
  out << YAML::Key << "pitch_rad" << YAML::Value << c.floor.pitch_rad;
  out << YAML::Key << "roll_rad" << YAML::Value << c.floor.roll_rad;
  out << YAML::Key << "distance_threshold_m" << YAML::Value << e.floor_fit.distance_threshold_m;
  out << YAML::Key << "min_width_m" << YAML::Value << e.floor_fit.min_width_m;
  out << YAML::Key << "max_tilt_rad" << YAML::Value << e.floor_fit.max_tilt_rad;
  out << YAML::EndMap;
  const StereoConfig& st = c.stereo;
  out << YAML::Key << "stereo" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "source" << YAML::Value << st.source;
  out << YAML::Key << "calibration" << YAML::Value << st.calibration;
  out << YAML::Key << "calibration_unit" << YAML::Value << st.calibration_unit;
  out << YAML::Key << "options" << YAML::Value << st.options;
  out << YAML::Key << "rate" << YAML::Value << (st.realtime ? "recorded" : "fast");
  out << YAML::Key << "loop" << YAML::Value << st.loop;
  out << YAML::Key << "fps" << YAML::Value << st.fps;
  out << YAML::Key << "stale_after_s" << YAML::Value << st.stale_after_s;
  out << YAML::EndMap;
  if (c.world_from_ground.configured) {
    out << YAML::Key << "world_from_ground" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "x_m" << YAML::Value << c.world_from_ground.x_m;
    out << YAML::Key << "y_m" << YAML::Value << c.world_from_ground.y_m;
    out << YAML::Key << "yaw_rad" << YAML::Value << c.world_from_ground.yaw_rad;
    out << YAML::EndMap;
  }
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

EstimatorOptions EffectiveEstimatorOptions(const DaemonConfig& config) {
  EstimatorOptions options = config.estimator;
  if (config.floor.fixed) {
    options.use_fixed_floor = true;
    options.fixed_floor = FloorEstimate::FromHeightPitchRoll(
        config.floor.height_m, config.floor.pitch_rad, config.floor.roll_rad);
  }
  return options;
}

}  // namespace hpose::server
