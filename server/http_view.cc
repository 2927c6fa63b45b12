#include "server/http_view.h"

#include <httplib.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstddef>
#include <functional>
#include <nlohmann/json.hpp>
#include <utility>

#include "server/elastic_task_queue.h"
#include "server/live_scene.h"
#include "server/message_json.h"
#include "server/metrics.h"
#include "server/pose_pipeline.h"
#include "server/pose_service.h"
#include "server/publish_signal.h"
#include "server/rpc_metrics_interceptor.h"
#include "server/stereo_pipeline.h"

namespace hpose::server {

// The live page (server/web/index.html), embedded at build time.
extern const char kWebPageHtml[];

namespace {

using Clock = std::chrono::steady_clock;

constexpr auto kEventWaitSlice = std::chrono::milliseconds(250);   // stop checks this often.
constexpr auto kEventHeartbeat = std::chrono::seconds(1);          // a message at least this often.
constexpr auto kEventMinInterval = std::chrono::milliseconds(50);  // at most 20 messages/s.
constexpr std::size_t kMaxRequestBodyBytes = 64 * 1024;            // no route takes a body.
constexpr int kRequestReadTimeoutS = 1;
// Workers the view may start: enough that connections stalled until their read times out do
// not hold up the others unless there are hundreds of them.
constexpr int kMaxWorkerThreads = 256;

// httplib's task queue on the ElasticTaskQueue.
class WebTaskQueue final : public httplib::TaskQueue {
 public:
  WebTaskQueue(int min_threads, int max_threads) : queue_(min_threads, max_threads) {}
  void enqueue(std::function<void()> job) override { queue_.Enqueue(std::move(job)); }
  void shutdown() override { queue_.Shutdown(); }

 private:
  ElasticTaskQueue queue_;
};

const char* kJson = "application/json";

int HttpCode(grpc::StatusCode code) {
  switch (code) {
    case grpc::StatusCode::INVALID_ARGUMENT:
      return 400;
    case grpc::StatusCode::NOT_FOUND:
      return 404;
    case grpc::StatusCode::FAILED_PRECONDITION:
      return 409;
    case grpc::StatusCode::UNAVAILABLE:
      return 503;
    default:
      return 500;
  }
}

std::string ErrorJson(const std::string& code, const std::string& message) {
  nlohmann::json e;
  e["code"] = code;
  e["message"] = message;
  return e.dump();
}

// "HOST:PORT" or "[V6]:PORT" -> host (without brackets) and port; false when malformed.
bool SplitListen(const std::string& listen, std::string* host, int* port) {
  const size_t colon = listen.rfind(':');
  if (colon == std::string::npos || colon == 0) return false;
  *host = listen.substr(0, colon);
  if (host->size() >= 2 && host->front() == '[' && host->back() == ']') {
    *host = host->substr(1, host->size() - 2);
  }
  try {
    size_t used = 0;
    *port = std::stoi(listen.substr(colon + 1), &used);
    return used == listen.size() - colon - 1 && *port >= 0 && *port <= 65535;
  } catch (const std::exception&) {
    return false;
  }
}

// The newest estimate of one estimator as PoseEstimate JSON, or null with the reason.
void LatestJson(const PoseServiceImpl& service, v1::EstimatorKind kind, nlohmann::ordered_json* out,
                const char* key) {
  v1::GetLatestResponse latest;
  const grpc::Status s = service.ReadLatest(kind, &latest);
  if (s.ok()) {
    (*out)[key] = nlohmann::ordered_json::parse(MessageToJsonLine(latest.estimate()));
    (*out)[std::string(key) + "_error"] = "";
  } else {
    (*out)[key] = nullptr;
    (*out)[std::string(key) + "_error"] = s.error_message();
  }
}

struct EventStreamState {
  bool first = true;
  std::uint64_t seen = 0;
  Clock::time_point sent;
};

}  // namespace

HttpView::HttpView(const HttpConfig& config, HttpViewSources sources)
    : config_(config),
      sources_(std::move(sources)),
      start_(Clock::now()),
      server_(std::make_unique<httplib::Server>()) {}

HttpView::~HttpView() { Stop(); }

Result<std::unique_ptr<HttpView>> HttpView::Start(const HttpConfig& config,
                                                  HttpViewSources sources) {
  std::string host;
  int port = 0;
  if (!SplitListen(config.listen, &host, &port)) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "http.listen: expected HOST:PORT, got '" + config.listen + "'");
  }
  std::unique_ptr<HttpView> view(new HttpView(config, std::move(sources)));
  const int threads = config.max_event_clients + 4;  // /events streams hold a thread each.
  view->server_->new_task_queue = [threads] {
    return new WebTaskQueue(threads, std::max(threads, kMaxWorkerThreads));
  };
  // Every route is a GET: a request body is never read, but without a limit the library would
  // buffer one of any announced size before answering (300 MB in, 650 MB of memory).
  view->server_->set_payload_max_length(kMaxRequestBodyBytes);
  // A worker waits this long for a request, or the rest of one, that does not come (a browser
  // sends it at once), so idle or stalled connections hold the pool's threads for about a
  // second each, not the library's default 5 (read) + 5 (keep-alive).
  view->server_->set_read_timeout(kRequestReadTimeoutS, 0);
  view->server_->set_keep_alive_timeout(kRequestReadTimeoutS);
  view->Routes();
  const int bound = port == 0 ? view->server_->bind_to_any_port(host)
                              : (view->server_->bind_to_port(host, port) ? port : -1);
  if (bound <= 0) {
    return MakeError(ErrorCode::kUnavailable,
                     "cannot serve the web view on '" + config.listen +
                         "' (address in use, or not an address of this machine)");
  }
  view->host_ = config.listen.substr(0, config.listen.rfind(':'));
  view->port_ = bound;
  httplib::Server* server = view->server_.get();
  view->thread_ = std::thread([server] { server->listen_after_bind(); });
  return view;
}

void HttpView::Stop() {
  if (stopping_.exchange(true)) return;
  server_->stop();
  if (thread_.joinable()) thread_.join();
}

std::string HttpView::Snapshot() const {
  nlohmann::ordered_json out;
  LatestJson(*sources_.service, v1::ESTIMATOR_KIND_DEPTH_TEMPLATE, &out, "latest");
  if (sources_.stereo != nullptr) {
    LatestJson(*sources_.service, v1::ESTIMATOR_KIND_STEREO_MARKER, &out, "stereo");
  } else {
    out["stereo"] = nullptr;
    out["stereo_error"] = "no stereo source";
  }
  v1::GetStatusResponse status;
  sources_.service->ReadStatus(&status);
  out["status"] = nlohmann::ordered_json::parse(MessageToJsonLine(status));
  out["scene"] = nlohmann::ordered_json::parse(sources_.scene->Json());
  return out.dump();
}

void HttpView::Routes() {
  httplib::Server& s = *server_;
  s.set_logger([](const httplib::Request& req, const httplib::Response& res) {
    spdlog::debug("http {} {} {} -> {}", req.remote_addr, req.method, req.path, res.status);
  });
  s.Get("/", [](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-store");
    res.set_content(kWebPageHtml, "text/html; charset=utf-8");
  });
  s.Get("/api/latest", [this](const httplib::Request& req, httplib::Response& res) {
    v1::EstimatorKind kind = v1::ESTIMATOR_KIND_UNSPECIFIED;
    const std::string which = req.get_param_value("estimator");
    if (which == "depth") {
      kind = v1::ESTIMATOR_KIND_DEPTH_TEMPLATE;
    } else if (which == "stereo") {
      kind = v1::ESTIMATOR_KIND_STEREO_MARKER;
    } else if (!which.empty()) {
      res.status = 400;
      res.set_content(
          ErrorJson("INVALID_ARGUMENT", "estimator: expected depth or stereo, got '" + which + "'"),
          kJson);
      return;
    }
    v1::GetLatestResponse latest;
    const grpc::Status st = sources_.service->ReadLatest(kind, &latest);
    if (!st.ok()) {
      res.status = HttpCode(st.error_code());
      res.set_content(ErrorJson(GrpcCodeName(st.error_code()), st.error_message()), kJson);
      return;
    }
    res.set_content(MessageToJsonLine(latest), kJson);
  });
  s.Get("/api/status", [this](const httplib::Request&, httplib::Response& res) {
    v1::GetStatusResponse status;
    sources_.service->ReadStatus(&status);
    res.set_content(MessageToJsonLine(status), kJson);
  });
  s.Get("/api/templates", [this](const httplib::Request&, httplib::Response& res) {
    v1::ListTemplatesResponse templates;
    sources_.service->ReadTemplates(&templates);
    res.set_content(MessageToJsonLine(templates), kJson);
  });
  s.Get("/api/scene", [this](const httplib::Request&, httplib::Response& res) {
    res.set_content(sources_.scene->Json(), kJson);
  });
  s.Get("/api/snapshot", [this](const httplib::Request&, httplib::Response& res) {
    res.set_content(Snapshot(), kJson);
  });
  s.Get("/metrics", [this](const httplib::Request&, httplib::Response& res) {
    std::vector<DaemonMetrics::Source> list;
    list.push_back({"depth", sources_.pipeline->Status()});
    if (sources_.stereo != nullptr) list.push_back({"stereo", sources_.stereo->Status()});
    const double uptime = std::chrono::duration<double>(Clock::now() - start_).count();
    res.set_content(sources_.metrics->Render(list, uptime, sources_.version),
                    "text/plain; version=0.0.4; charset=utf-8");
  });
  s.Get("/healthz", [this](const httplib::Request&, httplib::Response& res) {
    const PipelineStatus depth = sources_.pipeline->Status();
    const SourceState stereo =
        sources_.stereo != nullptr ? sources_.stereo->Status().state : SourceState::kNone;
    std::string reason;
    if (stopping_) reason = "shutting down";
    if (depth.state == SourceState::kFailed) reason = "depth source failed: " + depth.reason;
    if (stereo == SourceState::kFailed) reason = "stereo source failed";
    nlohmann::json out;
    out["healthy"] = reason.empty();
    out["reason"] = reason;
    out["source_state"] = SourceStateName(depth.state);
    out["stereo_source_state"] = SourceStateName(stereo);
    res.status = reason.empty() ? 200 : 503;
    res.set_content(out.dump(), kJson);
  });
  s.Get("/events", [this](const httplib::Request& req, httplib::Response& res) {
    if (event_clients_.fetch_add(1) >= config_.max_event_clients) {
      --event_clients_;
      res.status = 503;
      res.set_content(ErrorJson("RESOURCE_EXHAUSTED", std::to_string(config_.max_event_clients) +
                                                          " pages already follow the live view"),
                      kJson);
      return;
    }
    if (sources_.client_counter != nullptr) sources_.client_counter->ClientConnected("http_events");
    spdlog::info("web view: client {} connected", req.remote_addr);
    res.set_header("Cache-Control", "no-store");
    auto state = std::make_shared<EventStreamState>();
    res.set_chunked_content_provider(
        "text/event-stream",
        [this, state](size_t, httplib::DataSink& sink) {
          if (stopping_) return false;
          if (!state->first) {
            const bool changed =
                sources_.signal->WaitChange(state->seen, Clock::now() + kEventWaitSlice);
            const Clock::duration since = Clock::now() - state->sent;
            if (stopping_) return false;
            if (!changed && since < kEventHeartbeat) return true;
            if (since < kEventMinInterval) std::this_thread::sleep_for(kEventMinInterval - since);
          }
          state->first = false;
          state->seen = sources_.signal->count();
          state->sent = Clock::now();
          const std::string message = "data: " + Snapshot() + "\n\n";
          return sink.write(message.data(), message.size());
        },
        [this, addr = req.remote_addr](bool) {
          --event_clients_;
          if (sources_.client_counter != nullptr) {
            sources_.client_counter->ClientDisconnected("http_events");
          }
          spdlog::info("web view: client {} disconnected", addr);
        });
  });
}

}  // namespace hpose::server
