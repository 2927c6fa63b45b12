#include "server/grpc_listener.h"

#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>

#include <grpcpp/server_builder.h>
#include <spdlog/spdlog.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <utility>
#include <vector>

#include "server/descriptor_budget.h"
#include "server/tcp_listener.h"

namespace hpose::server {
namespace {

// The kernel's queue of connections not yet accepted: what a flood waits in.
constexpr int kBacklog = 4096;
// How often a listener that may not accept (or got no descriptor) looks again.
constexpr auto kRetry = std::chrono::milliseconds(10);

}  // namespace

Result<std::unique_ptr<GrpcListener>> GrpcListener::Bind(const std::string& host, int port) {
  Result<std::unique_ptr<TcpListener>> sockets = TcpListener::Listen(host, port, kBacklog);
  if (!sockets.ok()) return sockets.error();
  return std::unique_ptr<GrpcListener>(new GrpcListener(std::move(*sockets)));
}

GrpcListener::GrpcListener(std::unique_ptr<TcpListener> sockets) : sockets_(std::move(sockets)) {}

GrpcListener::~GrpcListener() { Stop(); }

int GrpcListener::port() const { return sockets_->port(); }

void GrpcListener::Start(grpc::experimental::ExternalConnectionAcceptor* acceptor) {
  accept_thread_ = std::thread([this, acceptor] { AcceptLoop(acceptor); });
}

void GrpcListener::Stop() {
  if (stopping_.exchange(true)) return;
  sockets_->Wake();
  if (accept_thread_.joinable()) accept_thread_.join();
}

void GrpcListener::AcceptLoop(grpc::experimental::ExternalConnectionAcceptor* acceptor) {
  std::vector<int> ready;
  auto last_warning = std::chrono::steady_clock::time_point();
  while (sockets_->Wait(&ready)) {
    for (std::size_t i = 0; i < ready.size() && !stopping_; ++i) {
      if (!MayAcceptConnection()) {
        const auto now = std::chrono::steady_clock::now();
        if (now - last_warning > std::chrono::seconds(10)) {
          last_warning = now;
          spdlog::warn(
              "gRPC: {} descriptors open, new connections wait (the last {} are kept for the "
              "frame source and files)",
              OpenDescriptors(), ReservedDescriptors());
        }
        std::this_thread::sleep_for(kRetry);
        continue;
      }
      const int fd = accept4(ready[i], nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK);
      if (fd < 0) {
        // Out of descriptors or memory after all: wait a little instead of spinning, and go on.
        if (errno == EMFILE || errno == ENFILE || errno == ENOBUFS || errno == ENOMEM) {
          std::this_thread::sleep_for(kRetry);
        }
        continue;  // EAGAIN, ECONNABORTED, EINTR: nothing to take, or gone already.
      }
      const int yes = 1;
      setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &yes, sizeof(yes));
      grpc::experimental::ExternalConnectionAcceptor::NewConnectionParameters connection;
      connection.listener_fd = ready[i];
      connection.fd = fd;  // the gRPC server's from now on (it closes it).
      acceptor->HandleNewConnection(&connection);
    }
  }
  if (!stopping_) spdlog::error("gRPC listener stopped: poll: {}", std::strerror(errno));
}

}  // namespace hpose::server
