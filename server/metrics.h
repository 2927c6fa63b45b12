#ifndef HPOSE_SERVER_METRICS_H_
#define HPOSE_SERVER_METRICS_H_

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "server/histogram.h"
#include "server/pose_pipeline.h"

namespace hpose::server {

// The web view's connections: open (read or served) and, of those, still sending their request
// head.
struct WebConnections {
  int open = 0;
  int reading = 0;
};

// The daemon's counters for /metrics (Prometheus text exposition format 0.0.4): per-stage
// estimate latency histograms, RPC outcomes by method and status code, clients connected.
// Frame counters and source states come from the pipelines' PipelineStatus when rendering.
// Thread-safe. docs/WEB.md lists every metric.
class DaemonMetrics final {
 public:
  // Stage names of hposed_estimate_stage_seconds, in the order rendered.
  static const std::vector<std::string>& StageNames();

  DaemonMetrics();

  // One published depth estimate: its estimator stages (when it succeeded), its wait in the
  // frame queue and its arrival-to-publication latency.
  void RecordDepthEstimate(const PublishedEstimate& e);
  // One finished RPC: `method` like "hpose.v1.PoseService/GetLatest", `code` like "OK".
  void RecordRpc(const std::string& method, const std::string& code);
  // Clients holding a connection open: kind "grpc_call" (calls in progress) or "http_events"
  // (web pages following /events).
  void ClientConnected(const std::string& kind);
  void ClientDisconnected(const std::string& kind);
  int clients(const std::string& kind) const;

  // A source to render: label value ("depth", "stereo") and its status.
  struct Source {
    std::string name;
    PipelineStatus status;
  };
  // The whole exposition, ending with a newline. The process's descriptors and their limit
  // (process_open_fds, process_max_fds) are read here.
  std::string Render(const std::vector<Source>& sources, double uptime_s,
                     const std::string& version, const WebConnections& web = {}) const;

 private:
  std::map<std::string, std::unique_ptr<Histogram>> stages_;
  mutable std::mutex mu_;  // guards the maps below.
  std::map<std::pair<std::string, std::string>, std::uint64_t> rpcs_;
  std::map<std::string, int> clients_;
};

// Escapes a Prometheus label value (backslash, double quote, newline).
std::string EscapeLabelValue(const std::string& value);

}  // namespace hpose::server

#endif  // HPOSE_SERVER_METRICS_H_
