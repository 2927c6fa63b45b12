#include "server/tcp_listener.h"

#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

namespace hpose::server {
namespace {

int PortOf(int fd) {
  sockaddr_storage bound{};
  socklen_t len = sizeof(bound);
  if (getsockname(fd, reinterpret_cast<sockaddr*>(&bound), &len) != 0) return 0;
  return ntohs(bound.ss_family == AF_INET6 ? reinterpret_cast<sockaddr_in6*>(&bound)->sin6_port
                                           : reinterpret_cast<sockaddr_in*>(&bound)->sin_port);
}

void SetPort(sockaddr* address, int port) {
  if (address->sa_family == AF_INET6) {
    reinterpret_cast<sockaddr_in6*>(address)->sin6_port = htons(static_cast<uint16_t>(port));
  } else if (address->sa_family == AF_INET) {
    reinterpret_cast<sockaddr_in*>(address)->sin_port = htons(static_cast<uint16_t>(port));
  }
}

// Why binding `host`:`port` failed with `err`, as a sentence.
std::string BindFailure(int err, const std::string& host, int port) {
  switch (err) {
    case EADDRINUSE:
      return "port " + std::to_string(port) + " is already in use (another hposed running?)";
    case EADDRNOTAVAIL:
      return "'" + host + "' is not an address of this machine";
    case EACCES:
      return "permission denied (ports below 1024 need privileges)";
    default:
      return std::strerror(err);
  }
}

}  // namespace

Result<HostPort> ParseHostPort(const std::string& listen) {
  const auto malformed = [&listen] {
    return MakeError(ErrorCode::kInvalidArgument,
                     "expected HOST:PORT with a port of 0-65535, got '" + listen + "'");
  };
  const size_t colon = listen.rfind(':');
  if (colon == std::string::npos || colon + 1 >= listen.size()) return malformed();
  HostPort out;
  for (size_t i = colon + 1; i < listen.size(); ++i) {
    if (listen[i] < '0' || listen[i] > '9') return malformed();
    out.port = out.port * 10 + (listen[i] - '0');
    if (out.port > 65535) return malformed();  // before it could overflow.
  }
  out.host = listen.substr(0, colon);
  if (out.host.size() >= 2 && out.host.front() == '[' && out.host.back() == ']') {
    out.host = out.host.substr(1, out.host.size() - 2);
  }
  if (out.host.empty()) return malformed();
  return out;
}

Result<std::unique_ptr<TcpListener>> TcpListener::Listen(const std::string& host, int port,
                                                         int backlog) {
  std::string name = host;
  if (name.size() >= 2 && name.front() == '[' && name.back() == ']') {
    name = name.substr(1, name.size() - 2);
  }
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
  addrinfo* found = nullptr;
  const std::string service = std::to_string(port);
  const int gai =
      getaddrinfo(name.empty() ? nullptr : name.c_str(), service.c_str(), &hints, &found);
  if (gai != 0) {
    return MakeError(ErrorCode::kUnavailable,
                     "the host '" + host + "' does not resolve (" + gai_strerror(gai) + ")");
  }
  std::vector<int> fds;
  int bound_port = port;
  std::string why;
  for (addrinfo* a = found; a != nullptr; a = a->ai_next) {
    const int fd =
        socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC | SOCK_NONBLOCK, a->ai_protocol);
    if (fd < 0) {
      if (why.empty()) why = std::string("cannot open a socket: ") + std::strerror(errno);
      continue;
    }
    const int yes = 1;
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
    if (a->ai_family == AF_INET6) {
      const int no = 0;  // a wildcard takes IPv4 too, as a dual-stack socket.
      setsockopt(fd, IPPROTO_IPV6, IPV6_V6ONLY, &no, sizeof(no));
    }
    // Every address on the port the first one got.
    if (bound_port != 0) SetPort(a->ai_addr, bound_port);
    if (bind(fd, a->ai_addr, a->ai_addrlen) != 0 || listen(fd, backlog) != 0) {
      // After a first address, a failure is the IPv4 wildcard a dual-stack socket already
      // holds, or an address family the machine does not serve: the others still listen. The
      // first failure is the one told.
      if (why.empty()) why = BindFailure(errno, name, bound_port);
      close(fd);
      continue;
    }
    if (bound_port == 0) bound_port = PortOf(fd);
    fds.push_back(fd);
  }
  freeaddrinfo(found);
  if (fds.empty()) {
    return MakeError(ErrorCode::kUnavailable, why.empty() ? "no address to listen on" : why);
  }
  int wake[2];
  if (pipe2(wake, O_CLOEXEC) != 0) {
    const int err = errno;
    for (int fd : fds) close(fd);
    return MakeError(ErrorCode::kUnavailable, std::string("pipe: ") + std::strerror(err));
  }
  return std::unique_ptr<TcpListener>(
      new TcpListener(std::move(fds), bound_port, wake[0], wake[1]));
}

TcpListener::TcpListener(std::vector<int> fds, int port, int wake_read, int wake_write)
    : fds_(std::move(fds)), port_(port), wake_read_(wake_read), wake_write_(wake_write) {}

TcpListener::~TcpListener() {
  for (int fd : fds_) close(fd);
  close(wake_read_);
  close(wake_write_);
}

bool TcpListener::Wait(std::vector<int>* ready) {
  ready->clear();
  std::vector<pollfd> polled;
  for (int fd : fds_) polled.push_back({fd, POLLIN, 0});
  polled.push_back({wake_read_, POLLIN, 0});
  while (true) {
    if (poll(polled.data(), polled.size(), -1) < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    if (polled.back().revents != 0) return false;  // the byte stays: later calls end too.
    for (std::size_t i = 0; i + 1 < polled.size(); ++i) {
      if ((polled[i].revents & POLLIN) != 0) ready->push_back(polled[i].fd);
    }
    if (!ready->empty()) return true;
  }
}

void TcpListener::Wake() {
  const char byte = 'x';
  [[maybe_unused]] const ssize_t n = write(wake_write_, &byte, 1);
}

}  // namespace hpose::server
