#include "server/tcp_listen.h"

#include <netdb.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

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

}  // namespace

Result<TcpListeners> ListenTcp(const std::string& host, int port, int backlog) {
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
                     "cannot resolve '" + host + "': " + gai_strerror(gai));
  }
  TcpListeners listeners;
  listeners.port = port;
  std::string why = "no address";
  for (addrinfo* a = found; a != nullptr; a = a->ai_next) {
    const int fd =
        socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC | SOCK_NONBLOCK, a->ai_protocol);
    if (fd < 0) {
      why = std::string("socket: ") + std::strerror(errno);
      continue;
    }
    const int yes = 1;
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
    if (a->ai_family == AF_INET6) {
      const int no = 0;  // a wildcard takes IPv4 too, as a dual-stack socket.
      setsockopt(fd, IPPROTO_IPV6, IPV6_V6ONLY, &no, sizeof(no));
    }
    // Every address on the port the first one got.
    if (listeners.port != 0) SetPort(a->ai_addr, listeners.port);
    if (bind(fd, a->ai_addr, a->ai_addrlen) != 0 || listen(fd, backlog) != 0) {
      // "Address already in use", "Cannot assign requested address". After a first address,
      // a failure is the IPv4 wildcard a dual-stack socket already holds, or an address family
      // the machine does not serve: the others still listen.
      why = std::strerror(errno);
      close(fd);
      continue;
    }
    if (listeners.port == 0) listeners.port = PortOf(fd);
    listeners.fds.push_back(fd);
  }
  freeaddrinfo(found);
  if (listeners.fds.empty()) return MakeError(ErrorCode::kUnavailable, why);
  return listeners;
}

}  // namespace hpose::server
