#ifndef HPOSE_SERVER_HTTP_SERVER_H_
#define HPOSE_SERVER_HTTP_SERVER_H_

#include <atomic>
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "core/common/status.h"
#include "server/http_message.h"

namespace hpose::server {

class ElasticTaskQueue;
class TcpListener;
class HttpHeadReader;
struct HttpHead;

// {"code": CODE, "message": MESSAGE}, the web view's error body (bytes that are not UTF-8 are
// replaced).
std::string HttpErrorJson(const std::string& code, const std::string& message);

struct HttpServerOptions {
  int min_threads = 4;    // workers kept ready.
  int max_threads = 256;  // workers at most; connections beyond wait for one.
  // Connections open at once (served or waiting for a worker). At the cap the server accepts
  // no more until one closes, and the kernel's backlog holds new ones: a flood of connections
  // cannot take the descriptors the rest of the daemon needs (a service's soft limit is
  // usually 1 024). The server also accepts only while MayAcceptConnection().
  int max_connections = 320;
  // A connection must deliver its whole request head within this once accepted (else it is
  // closed, with 408 when part of one came). Heads are read by one thread for all connections
  // (HttpHeadReader): one that stalls or trickles holds a descriptor until then, no worker.
  std::chrono::milliseconds head_timeout{2000};
  // A write that makes no progress for this long (a client that stopped reading) ends the
  // connection.
  std::chrono::milliseconds write_timeout{5000};
};

// The web view's HTTP/1.1 server: GET and HEAD only, one request a connection. It reads at
// most kMaxHttpHeadBytes of request head and never a body, so no client can make it buffer
// more: any other method gets 405 before its body is read, a head too large 431, a malformed
// one 400, an unknown path 404 (each with a JSON {"code", "message"}). Range requests are not
// served in parts: the whole answer, once.
class HttpServer {
 public:
  using Handler = std::function<void(const HttpRequest&, HttpResponse*)>;

  // Binds HOST:PORT (every address of a name, or a numeric IPv4 or IPv6 address; port 0 picks
  // a free port; see TcpListener::Listen). kUnavailable with a sentence naming the reason when
  // it cannot be bound.
  static Result<std::unique_ptr<HttpServer>> Bind(const std::string& host, int port,
                                                  const HttpServerOptions& options);
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  // Routes GET (and HEAD) of exactly `path`. Before Start.
  void Get(const std::string& path, Handler handler);
  // Logs each answered request (method, path, status). Before Start.
  void SetLogger(std::function<void(const HttpRequest&, int status)> logger);
  // Accepts connections on a thread of its own.
  void Start();
  // Stops accepting, then waits for the connections being served (streams end when their
  // callback returns false or a write times out). Idempotent.
  void Stop();
  int port() const;
  // Connections accepted and not yet closed; of those, the ones still sending their head.
  int open_connections() const { return open_connections_; }
  int reading_connections() const;

 private:
  HttpServer(std::unique_ptr<TcpListener> sockets, const HttpServerOptions& options);
  void AcceptLoop();
  void Serve(const HttpHead& head);
  void ServeConnection(const HttpHead& head);
  bool WriteAll(int fd, std::string_view data) const;
  void Answer(int fd, const HttpRequest& request, HttpResponse& response);

  const std::unique_ptr<TcpListener> sockets_;
  const HttpServerOptions options_;
  std::map<std::string, Handler> routes_;
  std::function<void(const HttpRequest&, int)> logger_;
  std::unique_ptr<ElasticTaskQueue> workers_;
  std::unique_ptr<HttpHeadReader> heads_;  // hands whole heads to workers_.
  std::thread accept_thread_;
  std::atomic<bool> stopping_{false};
  std::atomic<int> open_connections_{0};
};

}  // namespace hpose::server

#endif  // HPOSE_SERVER_HTTP_SERVER_H_
