#ifndef HPOSE_SERVER_GRPC_LISTENER_H_
#define HPOSE_SERVER_GRPC_LISTENER_H_

#include <atomic>
#include <memory>
#include <string>
#include <thread>

#include "core/common/status.h"

namespace grpc::experimental {
class ExternalConnectionAcceptor;
}  // namespace grpc::experimental

namespace hpose::server {

class TcpListener;

// Accepts the gRPC API's connections for the gRPC server, which then serves them as its own
// (TLS and all). gRPC's listener (1.51) stops for good the first time accept() fails for want
// of descriptors: a flood of idle connections, even once gone, left the daemon unreachable.
// This one accepts only while MayAcceptConnection() (a flood waits in the kernel's backlog, the
// frame source keeps descriptors to open its frames), and out of descriptors it waits and tries
// again.
class GrpcListener {
 public:
  // Listens on HOST:PORT (see TcpListener::Listen; port 0 picks one). kUnavailable with a
  // sentence naming the reason.
  static Result<std::unique_ptr<GrpcListener>> Bind(const std::string& host, int port);
  ~GrpcListener();
  GrpcListener(const GrpcListener&) = delete;
  GrpcListener& operator=(const GrpcListener&) = delete;

  // Hands each accepted connection to `acceptor`, which must outlive Stop(), on a thread of its
  // own.
  void Start(grpc::experimental::ExternalConnectionAcceptor* acceptor);
  // Stops accepting (connections already handed over are the gRPC server's). Idempotent.
  void Stop();
  int port() const;

 private:
  explicit GrpcListener(std::unique_ptr<TcpListener> sockets);
  void AcceptLoop(grpc::experimental::ExternalConnectionAcceptor* acceptor);

  const std::unique_ptr<TcpListener> sockets_;
  std::thread accept_thread_;
  std::atomic<bool> stopping_{false};
};

}  // namespace hpose::server

#endif  // HPOSE_SERVER_GRPC_LISTENER_H_
