#ifndef HPOSE_SERVER_HTTP_VIEW_H_
#define HPOSE_SERVER_HTTP_VIEW_H_

#include <atomic>
#include <chrono>
#include <memory>
#include <string>
#include <thread>

#include "core/common/status.h"
#include "server/daemon_config.h"

namespace hpose::server {

class DaemonMetrics;
class HttpServer;
class LiveScene;
class PosePipeline;
class PoseServiceImpl;
class PublishSignal;
class StereoPipeline;

// What the web view reads. Everything must outlive the view; `stereo` may be null.
struct HttpViewSources {
  const PoseServiceImpl* service = nullptr;
  const PosePipeline* pipeline = nullptr;
  const StereoPipeline* stereo = nullptr;
  const PublishSignal* signal = nullptr;
  const DaemonMetrics* metrics = nullptr;
  const LiveScene* scene = nullptr;
  DaemonMetrics* client_counter = nullptr;  // counts pages following /events (may be metrics).
  std::string version;
};

// hposed's plain-HTTP side (docs/WEB.md): the live page (/), its JSON (/api/latest,
// /api/status, /api/templates, /api/scene) and update stream (/events, Server-Sent Events),
// /metrics (Prometheus text) and /healthz. Read only, on HttpServer.
class HttpView {
 public:
  // Binds `config.listen` (port 0 picks a free port); connections wait in the kernel's queue
  // until Start. kUnavailable naming the address and the reason when it cannot bind.
  static Result<std::unique_ptr<HttpView>> Bind(const HttpConfig& config);
  // Serves what `sources` hold on a thread of its own. Once.
  void Start(HttpViewSources sources);
  ~HttpView();

  int port() const { return port_; }
  std::string address() const { return host_ + ":" + std::to_string(port_); }

  // Ends /events streams and stops serving. Idempotent.
  void Stop();

 private:
  explicit HttpView(const HttpConfig& config);
  void Routes();
  // One /events message: the newest estimates, status and scene as a JSON object.
  std::string Snapshot() const;

  const HttpConfig config_;
  HttpViewSources sources_;  // set by Start.
  const std::chrono::steady_clock::time_point start_;
  std::unique_ptr<HttpServer> server_;
  std::string host_;
  int port_ = 0;
  std::atomic<bool> stopping_{false};
  std::atomic<int> event_clients_{0};
};

}  // namespace hpose::server

#endif  // HPOSE_SERVER_HTTP_VIEW_H_
