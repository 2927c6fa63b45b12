#include "server/grpc_listener.h"

#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <grpcpp/server_builder.h>
#include <spdlog/spdlog.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <utility>

#include "server/descriptor_budget.h"
#include "server/tcp_listen.h"

namespace hpose::server {
namespace {

// The kernel's queue of connections not yet accepted: what a flood waits in.
constexpr int kBacklog = 4096;
// How often a listener that may not accept (or got no descriptor) looks again.
constexpr auto kRetry = std::chrono::milliseconds(10);

}  // namespace

Result<std::unique_ptr<GrpcListener>> GrpcListener::Bind(const std::string& host, int port) {
  Result<TcpListeners> bound = ListenTcp(host, port, kBacklog);
  if (!bound.ok()) return bound.error();
  std::unique_ptr<GrpcListener> listener(new GrpcListener(bound->fds, bound->port));
  if (pipe2(listener->wake_fds_, O_CLOEXEC) != 0) {
    return MakeError(ErrorCode::kUnavailable, std::string("pipe: ") + std::strerror(errno));
  }
  return listener;
}

GrpcListener::GrpcListener(std::vector<int> listen_fds, int port)
    : listen_fds_(std::move(listen_fds)), port_(port) {}

GrpcListener::~GrpcListener() {
  Stop();
  for (int fd : listen_fds_) close(fd);
  for (int fd : wake_fds_) {
    if (fd >= 0) close(fd);
  }
}

void GrpcListener::Start(grpc::experimental::ExternalConnectionAcceptor* acceptor) {
  accept_thread_ = std::thread([this, acceptor] { AcceptLoop(acceptor); });
}

void GrpcListener::Stop() {
  if (stopping_.exchange(true)) return;
  if (wake_fds_[1] >= 0) {
    const char byte = 'x';
    [[maybe_unused]] const ssize_t n = write(wake_fds_[1], &byte, 1);
  }
  if (accept_thread_.joinable()) accept_thread_.join();
}

void GrpcListener::AcceptLoop(grpc::experimental::ExternalConnectionAcceptor* acceptor) {
  std::vector<pollfd> fds;
  for (int fd : listen_fds_) fds.push_back({fd, POLLIN, 0});
  fds.push_back({wake_fds_[0], POLLIN, 0});
  auto last_warning = std::chrono::steady_clock::time_point();
  while (!stopping_) {
    for (pollfd& p : fds) p.revents = 0;
    if (poll(fds.data(), fds.size(), -1) < 0) {
      if (errno == EINTR) continue;
      spdlog::error("gRPC listener: poll: {}", std::strerror(errno));
      return;
    }
    if (fds.back().revents != 0) return;
    for (std::size_t i = 0; i + 1 < fds.size() && !stopping_; ++i) {
      if ((fds[i].revents & POLLIN) == 0) continue;
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
      const int fd = accept4(fds[i].fd, nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK);
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
      connection.listener_fd = fds[i].fd;
      connection.fd = fd;  // the gRPC server's from now on (it closes it).
      acceptor->HandleNewConnection(&connection);
    }
  }
}

}  // namespace hpose::server
