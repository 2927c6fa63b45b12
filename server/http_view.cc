#include "server/http_view.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstddef>
#include <functional>
#include <nlohmann/json.hpp>
#include <utility>

#include "server/http_server.h"
#include "server/live_scene.h"
#include "server/message_json.h"
#include "server/metrics.h"
#include "server/pose_pipeline.h"
#include "server/pose_service.h"
#include "server/publish_signal.h"
#include "server/rpc_metrics_interceptor.h"
#include "server/stereo_pipeline.h"
#include "server/tcp_listener.h"

namespace hpose::server {

// The live page (server/web/index.html), embedded at build time.
extern const char kWebPageHtml[];

namespace {

using Clock = std::chrono::steady_clock;

constexpr auto kEventWaitSlice = std::chrono::milliseconds(250);   // stop checks this often.
constexpr auto kEventHeartbeat = std::chrono::seconds(1);          // a message at least this often.
constexpr auto kEventMinInterval = std::chrono::milliseconds(50);  // at most 20 messages/s.
// Workers the view may start: enough that connections stalled until their head's deadline do
// not hold up the others unless there are hundreds of them.
constexpr int kMaxWorkerThreads = 256;

const char* kJson = "application/json";

void SetContent(HttpResponse* res, std::string body, const char* type) {
  res->body = std::move(body);
  res->content_type = type;
}

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

HttpView::HttpView(const HttpConfig& config)
    : config_(config), start_(Clock::now()), server_(nullptr) {}

HttpView::~HttpView() { Stop(); }

Result<std::unique_ptr<HttpView>> HttpView::Bind(const HttpConfig& config) {
  Result<HostPort> address = ParseHostPort(config.listen);
  if (!address.ok()) {
    return MakeError(address.error().code, "http.listen: " + address.error().message);
  }
  HttpServerOptions options;
  options.min_threads = config.max_event_clients + 4;  // /events streams hold a worker each.
  options.max_threads = std::max(options.min_threads, kMaxWorkerThreads);
  options.max_connections = options.max_threads + 64;
  Result<std::unique_ptr<HttpServer>> bound =
      HttpServer::Bind(address->host, address->port, options);
  if (!bound.ok()) {
    return MakeError(ErrorCode::kUnavailable, "cannot serve the web view on '" + config.listen +
                                                  "' (http.listen): " + bound.error().message);
  }
  std::unique_ptr<HttpView> view(new HttpView(config));
  view->server_ = std::move(bound).value();
  view->host_ = config.listen.substr(0, config.listen.rfind(':'));
  view->port_ = view->server_->port();
  return view;
}

void HttpView::Start(HttpViewSources sources) {
  sources_ = std::move(sources);
  Routes();
  server_->Start();
}

void HttpView::Stop() {
  if (stopping_.exchange(true)) return;
  server_->Stop();
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
  HttpServer& s = *server_;
  s.SetLogger([](const HttpRequest& req, int status) {
    spdlog::debug("http {} {} {} -> {}", req.remote_addr, req.method, req.path, status);
  });
  s.Get("/", [](const HttpRequest&, HttpResponse* res) {
    res->headers.emplace_back("Cache-Control", "no-store");
    SetContent(res, kWebPageHtml, "text/html; charset=utf-8");
  });
  s.Get("/api/latest", [this](const HttpRequest& req, HttpResponse* res) {
    v1::EstimatorKind kind = v1::ESTIMATOR_KIND_UNSPECIFIED;
    const std::string which = req.Param("estimator");
    if (which == "depth") {
      kind = v1::ESTIMATOR_KIND_DEPTH_TEMPLATE;
    } else if (which == "stereo") {
      kind = v1::ESTIMATOR_KIND_STEREO_MARKER;
    } else if (!which.empty()) {
      res->status = 400;
      SetContent(res,
                 HttpErrorJson("INVALID_ARGUMENT",
                               "estimator: expected depth or stereo, got '" + which + "'"),
                 kJson);
      return;
    }
    v1::GetLatestResponse latest;
    const grpc::Status st = sources_.service->ReadLatest(kind, &latest);
    if (!st.ok()) {
      res->status = HttpCode(st.error_code());
      SetContent(res, HttpErrorJson(GrpcCodeName(st.error_code()), st.error_message()), kJson);
      return;
    }
    SetContent(res, MessageToJsonLine(latest), kJson);
  });
  s.Get("/api/status", [this](const HttpRequest&, HttpResponse* res) {
    v1::GetStatusResponse status;
    sources_.service->ReadStatus(&status);
    SetContent(res, MessageToJsonLine(status), kJson);
  });
  s.Get("/api/templates", [this](const HttpRequest&, HttpResponse* res) {
    v1::ListTemplatesResponse templates;
    sources_.service->ReadTemplates(&templates);
    SetContent(res, MessageToJsonLine(templates), kJson);
  });
  s.Get("/api/scene", [this](const HttpRequest&, HttpResponse* res) {
    SetContent(res, sources_.scene->Json(), kJson);
  });
  s.Get("/api/snapshot",
        [this](const HttpRequest&, HttpResponse* res) { SetContent(res, Snapshot(), kJson); });
  s.Get("/metrics", [this](const HttpRequest&, HttpResponse* res) {
    std::vector<DaemonMetrics::Source> list;
    list.push_back({"depth", sources_.pipeline->Status()});
    if (sources_.stereo != nullptr) list.push_back({"stereo", sources_.stereo->Status()});
    const double uptime = std::chrono::duration<double>(Clock::now() - start_).count();
    WebConnections web;
    web.open = server_->open_connections();
    web.reading = server_->reading_connections();
    SetContent(res, sources_.metrics->Render(list, uptime, sources_.version, web),
               "text/plain; version=0.0.4; charset=utf-8");
  });
  s.Get("/healthz", [this](const HttpRequest&, HttpResponse* res) {
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
    res->status = reason.empty() ? 200 : 503;
    SetContent(res, out.dump(), kJson);
  });
  s.Get("/events", [this](const HttpRequest& req, HttpResponse* res) {
    if (event_clients_.fetch_add(1) >= config_.max_event_clients) {
      --event_clients_;
      res->status = 503;
      SetContent(res,
                 HttpErrorJson("RESOURCE_EXHAUSTED", std::to_string(config_.max_event_clients) +
                                                         " pages already follow the live view"),
                 kJson);
      return;
    }
    if (sources_.client_counter != nullptr) sources_.client_counter->ClientConnected("http_events");
    spdlog::info("web view: client {} connected", req.remote_addr);
    res->headers.emplace_back("Cache-Control", "no-store");
    auto state = std::make_shared<EventStreamState>();
    res->content_type = "text/event-stream";
    res->stream = [this, state](const HttpResponse::Writer& write) {
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
      return write(message);
    };
    res->stream_done = [this, addr = req.remote_addr] {
      --event_clients_;
      if (sources_.client_counter != nullptr) {
        sources_.client_counter->ClientDisconnected("http_events");
      }
      spdlog::info("web view: client {} disconnected", addr);
    };
  });
}

}  // namespace hpose::server
