#include "server/http_server.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <exception>
#include <nlohmann/json.hpp>
#include <utility>

#include "server/descriptor_budget.h"
#include "server/elastic_task_queue.h"
#include "server/http_head_reader.h"
#include "server/http_request_parser.h"
#include "server/tcp_listener.h"

namespace hpose::server {

namespace {

using Clock = std::chrono::steady_clock;

// After an answer the connection is closed; what the client still sends (an unread body) is
// read and dropped for at most this long and this much first, so that closing with unread
// bytes (which resets the connection) does not discard the answer at the client.
constexpr auto kDrainTime = std::chrono::milliseconds(100);
constexpr std::size_t kDrainBytes = 64 * 1024;

const char* Reason(int status) {
  switch (status) {
    case 200:
      return "OK";
    case 400:
      return "Bad Request";
    case 404:
      return "Not Found";
    case 405:
      return "Method Not Allowed";
    case 408:
      return "Request Timeout";
    case 409:
      return "Conflict";
    case 431:
      return "Request Header Fields Too Large";
    case 500:
      return "Internal Server Error";
    case 503:
      return "Service Unavailable";
    default:
      return "Status";
  }
}

int MillisecondsUntil(Clock::time_point t) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(t - Clock::now());
  return static_cast<int>(std::max<std::chrono::milliseconds::rep>(0, left.count()));
}

std::string PeerAddress(int fd) {
  sockaddr_storage addr{};
  socklen_t len = sizeof(addr);
  if (getpeername(fd, reinterpret_cast<sockaddr*>(&addr), &len) != 0) return "?";
  char text[INET6_ADDRSTRLEN] = "?";
  if (addr.ss_family == AF_INET) {
    inet_ntop(AF_INET, &reinterpret_cast<sockaddr_in*>(&addr)->sin_addr, text, sizeof(text));
  } else if (addr.ss_family == AF_INET6) {
    inet_ntop(AF_INET6, &reinterpret_cast<sockaddr_in6*>(&addr)->sin6_addr, text, sizeof(text));
  }
  return text;
}

HttpResponse ErrorResponse(int status, const char* code, const std::string& message) {
  HttpResponse response;
  response.status = status;
  response.content_type = "application/json";
  response.body = HttpErrorJson(code, message);
  return response;
}

}  // namespace

std::string HttpErrorJson(const std::string& code, const std::string& message) {
  nlohmann::json e;
  e["code"] = code;
  e["message"] = message;
  // A message may quote a client's bytes that are not UTF-8: replaced, never thrown over.
  return e.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

Result<std::unique_ptr<HttpServer>> HttpServer::Bind(const std::string& host, int port,
                                                     const HttpServerOptions& options) {
  Result<std::unique_ptr<TcpListener>> sockets = TcpListener::Listen(host, port, 128);
  if (!sockets.ok()) return sockets.error();
  std::unique_ptr<HttpServer> server(new HttpServer(std::move(*sockets), options));
  Result<std::unique_ptr<HttpHeadReader>> heads = HttpHeadReader::Start(
      options.head_timeout, kMaxHttpHeadBytes, [s = server.get()](HttpHead head) {
        s->workers_->Enqueue([s, head = std::move(head)] { s->Serve(head); });
      });
  if (!heads.ok()) return heads.error();
  server->heads_ = std::move(*heads);
  return server;
}

HttpServer::HttpServer(std::unique_ptr<TcpListener> sockets, const HttpServerOptions& options)
    : sockets_(std::move(sockets)),
      options_(options),
      workers_(std::make_unique<ElasticTaskQueue>(
          options.min_threads, std::max(options.min_threads, options.max_threads))) {}

HttpServer::~HttpServer() { Stop(); }

int HttpServer::port() const { return sockets_->port(); }

int HttpServer::reading_connections() const { return heads_->reading(); }

void HttpServer::Get(const std::string& path, Handler handler) {
  routes_[path] = std::move(handler);
}

void HttpServer::SetLogger(std::function<void(const HttpRequest&, int)> logger) {
  logger_ = std::move(logger);
}

void HttpServer::Start() {
  accept_thread_ = std::thread([this] { AcceptLoop(); });
}

void HttpServer::Stop() {
  if (stopping_.exchange(true)) return;
  sockets_->Wake();
  if (accept_thread_.joinable()) accept_thread_.join();
  if (heads_) heads_->Stop();  // what it still reads goes to the workers, which close it.
  workers_->Shutdown();
}

void HttpServer::AcceptLoop() {
  std::vector<int> ready;
  while (sockets_->Wait(&ready)) {
    for (std::size_t i = 0; i < ready.size() && !stopping_; ++i) {
      if (open_connections_ >= options_.max_connections || !MayAcceptConnection()) {
        std::this_thread::sleep_for(std::chrono::milliseconds(5));  // until one closes.
        continue;
      }
      const int fd = accept4(ready[i], nullptr, nullptr, SOCK_CLOEXEC);
      if (fd < 0) {
        // Out of descriptors or memory: wait a little instead of spinning.
        if (errno == EMFILE || errno == ENFILE || errno == ENOBUFS || errno == ENOMEM) {
          std::this_thread::sleep_for(std::chrono::milliseconds(10));
        }
        continue;
      }
      ++open_connections_;
      heads_->Add(fd);
    }
  }
}

bool HttpServer::WriteAll(int fd, std::string_view data) const {
  while (!data.empty()) {
    const ssize_t n = send(fd, data.data(), data.size(), MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;  // the peer is gone, or SO_SNDTIMEO passed without progress.
    data.remove_prefix(static_cast<std::size_t>(n));
  }
  return true;
}

void HttpServer::Serve(const HttpHead& head) {
  if (!stopping_) ServeConnection(head);
  close(head.fd);
  --open_connections_;
}

void HttpServer::ServeConnection(const HttpHead& head) {
  const int fd = head.fd;
  const auto write_ms = options_.write_timeout.count();
  timeval send_timeout{};
  send_timeout.tv_sec = static_cast<time_t>(write_ms / 1000);
  send_timeout.tv_usec = static_cast<suseconds_t>((write_ms % 1000) * 1000);
  setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &send_timeout, sizeof(send_timeout));

  HttpRequest request;
  request.remote_addr = PeerAddress(fd);
  HttpResponse response;
  if (head.end == std::string_view::npos) {
    if (head.closed || head.bytes.empty()) return;  // nothing asked, or the client went away.
    response = head.too_large
                   ? ErrorResponse(
                         431, "OUT_OF_RANGE",
                         "request head larger than " + std::to_string(kMaxHttpHeadBytes) + " bytes")
                   : ErrorResponse(408, "DEADLINE_EXCEEDED",
                                   "the request head did not come within " +
                                       std::to_string(options_.head_timeout.count()) + " ms");
  } else {
    Result<HttpRequest> parsed =
        ParseHttpRequestHead(std::string_view(head.bytes).substr(0, head.end));
    if (!parsed.ok()) {
      const bool too_large = parsed.error().code == ErrorCode::kOutOfRange;
      response =
          ErrorResponse(too_large ? 431 : 400, too_large ? "OUT_OF_RANGE" : "INVALID_ARGUMENT",
                        parsed.error().message);
    } else {
      const std::string addr = request.remote_addr;
      request = std::move(parsed).value();
      request.remote_addr = addr;
      const auto route = routes_.find(request.path);
      if (request.method != "GET" && request.method != "HEAD") {
        response = ErrorResponse(405, "INVALID_ARGUMENT",
                                 "the web view answers GET only, not " + request.method);
        response.headers.emplace_back("Allow", "GET, HEAD");
      } else if (route == routes_.end()) {
        response = ErrorResponse(404, "NOT_FOUND", "no page " + request.path.substr(0, 200));
      } else {
        try {
          route->second(request, &response);
        } catch (const std::exception& e) {
          response = ErrorResponse(500, "INTERNAL", e.what());
        }
      }
    }
  }
  Answer(fd, request, response);
  if (logger_) logger_(request, response.status);

  // Close without resetting the connection over an unread body (see kDrainTime).
  shutdown(fd, SHUT_WR);
  const Clock::time_point drain_end = Clock::now() + kDrainTime;
  std::size_t drained = 0;
  char chunk[4096];
  while (drained < kDrainBytes) {
    pollfd p{fd, POLLIN, 0};
    if (poll(&p, 1, MillisecondsUntil(drain_end)) <= 0) break;
    const ssize_t n = recv(fd, chunk, sizeof(chunk), 0);
    if (n <= 0) break;
    drained += static_cast<std::size_t>(n);
  }
}

void HttpServer::Answer(int fd, const HttpRequest& request, HttpResponse& response) {
  std::string head = "HTTP/1.1 " + std::to_string(response.status) + " " + Reason(response.status) +
                     "\r\nContent-Type: " + response.content_type + "\r\n";
  for (const auto& [name, value] : response.headers) head += name + ": " + value + "\r\n";
  if (!response.stream) head += "Content-Length: " + std::to_string(response.body.size()) + "\r\n";
  head += "Connection: close\r\n\r\n";
  const bool head_only = request.method == "HEAD";
  if (!response.stream) {
    if (!head_only) head += response.body;
    WriteAll(fd, head);
    return;
  }
  if (WriteAll(fd, head) && !head_only) {
    const HttpResponse::Writer write = [this, fd](std::string_view data) {
      return !stopping_ && WriteAll(fd, data);
    };
    while (response.stream(write)) {
    }
  }
  if (response.stream_done) response.stream_done();
}

}  // namespace hpose::server
