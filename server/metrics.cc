#include "server/metrics.h"

#include <sys/resource.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "server/descriptor_budget.h"

namespace hpose::server {

namespace {

constexpr SourceState kAllStates[] = {SourceState::kNone,     SourceState::kStarting,
                                      SourceState::kRunning,  SourceState::kReconnecting,
                                      SourceState::kFinished, SourceState::kFailed};

// A sample value as Prometheus reads it (Go's float syntax; +Inf, -Inf, NaN spelled out).
std::string Value(double v) {
  if (std::isnan(v)) return "NaN";
  if (std::isinf(v)) return v > 0 ? "+Inf" : "-Inf";
  char buf[40];
  // Whole numbers (counters, counts) in full: 10 frames read 10, not the 1e+01 that the
  // shortest form below would give.
  if (v == std::trunc(v) && std::abs(v) < 1e15) {
    std::snprintf(buf, sizeof(buf), "%.0f", v);
    return buf;
  }
  // The shortest decimal that reads back as the same double (bucket bounds read 0.512, not
  // 0.51200000000000001).
  for (int precision = 1; precision <= 17; ++precision) {
    std::snprintf(buf, sizeof(buf), "%.*g", precision, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  return buf;
}

void Header(std::ostringstream& out, const std::string& name, const std::string& type,
            const std::string& help) {
  out << "# HELP " << name << ' ' << help << "\n# TYPE " << name << ' ' << type << '\n';
}

// A counter or gauge per source, from a field of its status.
template <typename Get>
void PerSource(std::ostringstream& out, const std::vector<DaemonMetrics::Source>& sources,
               const std::string& name, const std::string& type, const std::string& help, Get get) {
  Header(out, name, type, help);
  for (const DaemonMetrics::Source& s : sources) {
    out << name << "{source=\"" << EscapeLabelValue(s.name) << "\"} " << Value(get(s.status))
        << '\n';
  }
}

}  // namespace

std::string EscapeLabelValue(const std::string& value) {
  std::string out;
  for (const char c : value) {
    if (c == '\\') {
      out += "\\\\";
    } else if (c == '"') {
      out += "\\\"";
    } else if (c == '\n') {
      out += "\\n";
    } else {
      out += c;
    }
  }
  return out;
}

const std::vector<std::string>& DaemonMetrics::StageNames() {
  static const std::vector<std::string> kNames = {"cloud",  "floor",    "cluster", "search",
                                                  "refine", "estimate", "queue",   "latency"};
  return kNames;
}

DaemonMetrics::DaemonMetrics() {
  // 0.5 ms to 16 s, doubling.
  const std::vector<double> bounds = Histogram::ExponentialBounds(0.0005, 2.0, 16);
  for (const std::string& stage : StageNames()) {
    stages_.emplace(stage, std::make_unique<Histogram>(bounds));
  }
}

void DaemonMetrics::RecordDepthEstimate(const PublishedEstimate& e) {
  if (e.ok) {
    const StageTimings& t = e.estimate.timings;
    stages_.at("cloud")->Observe(t.cloud_ms / 1000.0);
    stages_.at("floor")->Observe(t.floor_ms / 1000.0);
    stages_.at("cluster")->Observe(t.cluster_ms / 1000.0);
    stages_.at("search")->Observe(t.search_ms / 1000.0);
    stages_.at("refine")->Observe(t.refine_ms / 1000.0);
    stages_.at("estimate")->Observe(t.total_ms / 1000.0);
  }
  stages_.at("queue")->Observe(e.queue_s);
  stages_.at("latency")->Observe(e.latency_s);
}

void DaemonMetrics::RecordRpc(const std::string& method, const std::string& code) {
  std::lock_guard<std::mutex> lock(mu_);
  ++rpcs_[{method, code}];
}

void DaemonMetrics::ClientConnected(const std::string& kind) {
  std::lock_guard<std::mutex> lock(mu_);
  ++clients_[kind];
}

void DaemonMetrics::ClientDisconnected(const std::string& kind) {
  std::lock_guard<std::mutex> lock(mu_);
  --clients_[kind];
}

int DaemonMetrics::clients(const std::string& kind) const {
  std::lock_guard<std::mutex> lock(mu_);
  const auto it = clients_.find(kind);
  return it == clients_.end() ? 0 : it->second;
}

std::string DaemonMetrics::Render(const std::vector<Source>& sources, double uptime_s,
                                  const std::string& version, const WebConnections& web) const {
  std::ostringstream out;
  Header(out, "hposed_build_info", "gauge", "The daemon's version (value always 1).");
  out << "hposed_build_info{version=\"" << EscapeLabelValue(version) << "\"} 1\n";
  Header(out, "hposed_uptime_seconds", "gauge", "Seconds since the daemon started.");
  out << "hposed_uptime_seconds " << Value(uptime_s) << '\n';
  PerSource(out, sources, "hposed_frames_received_total", "counter", "Frames read from the source.",
            [](const PipelineStatus& s) { return s.frames_in; });
  PerSource(out, sources, "hposed_frames_estimated_total", "counter",
            "Frames whose estimate was published without error.",
            [](const PipelineStatus& s) { return s.frames_estimated; });
  PerSource(out, sources, "hposed_frames_dropped_total", "counter",
            "Frames dropped unestimated because a newer frame arrived first.",
            [](const PipelineStatus& s) { return s.frames_dropped; });
  PerSource(out, sources, "hposed_frames_failed_total", "counter",
            "Frames that could not be read or estimated (e.g. no floor).",
            [](const PipelineStatus& s) { return s.frames_failed; });
  PerSource(out, sources, "hposed_source_reconnects_total", "counter",
            "Times a live source was reopened after a loss.",
            [](const PipelineStatus& s) { return s.reconnects; });
  PerSource(out, sources, "hposed_estimate_rate_hertz", "gauge",
            "Estimates published per second over the last few seconds.",
            [](const PipelineStatus& s) { return s.estimate_rate_hz; });
  Header(out, "hposed_source_state", "gauge",
         "1 for the state each source is in, 0 for the others.");
  for (const Source& s : sources) {
    for (const SourceState state : kAllStates) {
      out << "hposed_source_state{source=\"" << EscapeLabelValue(s.name) << "\",state=\""
          << SourceStateName(state) << "\"} " << (s.status.state == state ? 1 : 0) << '\n';
    }
  }
  Header(out, "hposed_estimate_stage_seconds", "histogram",
         "Depth estimate time by stage: cloud, floor, cluster, search, refine (part of search) "
         "and estimate (all estimator stages); queue (waiting for the estimator) and latency "
         "(frame arrival to publication).");
  for (const std::string& stage : StageNames()) {
    const Histogram::Snapshot h = stages_.at(stage)->Read();
    const std::string labels = "stage=\"" + stage + "\"";
    for (size_t i = 0; i < h.upper_bounds.size(); ++i) {
      out << "hposed_estimate_stage_seconds_bucket{" << labels << ",le=\""
          << Value(h.upper_bounds[i]) << "\"} " << h.cumulative[i] << '\n';
    }
    out << "hposed_estimate_stage_seconds_bucket{" << labels << ",le=\"+Inf\"} " << h.count << '\n';
    out << "hposed_estimate_stage_seconds_sum{" << labels << "} " << Value(h.sum) << '\n';
    out << "hposed_estimate_stage_seconds_count{" << labels << "} " << h.count << '\n';
  }
  std::lock_guard<std::mutex> lock(mu_);
  Header(out, "hposed_clients_connected", "gauge",
         "Clients connected: gRPC calls in progress (grpc_call) and web pages following the "
         "live view (http_events).");
  for (const char* kind : {"grpc_call", "http_events"}) {
    const auto it = clients_.find(kind);
    out << "hposed_clients_connected{kind=\"" << kind << "\"} "
        << (it == clients_.end() ? 0 : it->second) << '\n';
  }
  Header(out, "hposed_http_connections", "gauge",
         "Web view connections open (read or served) and, of those, still sending their request "
         "head (reading).");
  out << "hposed_http_connections{state=\"open\"} " << web.open << '\n';
  out << "hposed_http_connections{state=\"reading\"} " << web.reading << '\n';
  // The names Prometheus's client libraries give these. The network servers stop accepting
  // short of the limit (docs/RELIABILITY.md, "Connections").
  const int open_fds = OpenDescriptors();
  if (open_fds >= 0) {
    Header(out, "process_open_fds", "gauge", "Open file descriptors.");
    out << "process_open_fds " << open_fds << '\n';
  }
  rlimit limit{};
  if (getrlimit(RLIMIT_NOFILE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY) {
    Header(out, "process_max_fds", "gauge", "The soft limit on open file descriptors.");
    out << "process_max_fds " << limit.rlim_cur << '\n';
  }
  Header(out, "hposed_rpc_total", "counter", "Finished gRPC calls by method and status code.");
  for (const auto& [key, count] : rpcs_) {
    out << "hposed_rpc_total{method=\"" << EscapeLabelValue(key.first) << "\",code=\""
        << EscapeLabelValue(key.second) << "\"} " << count << '\n';
  }
  return out.str();
}

}  // namespace hpose::server
