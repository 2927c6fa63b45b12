#include "server/listen_check.h"

#include <netdb.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace hpose::server {

Status CheckCanListen(const std::string& listen) {
  const size_t colon = listen.rfind(':');
  if (colon == std::string::npos) return Status::Ok();  // the config check explains this one.
  std::string host = listen.substr(0, colon);
  const std::string port = listen.substr(colon + 1);
  if (port == "0" || port.empty()) return Status::Ok();
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') {
    host = host.substr(1, host.size() - 2);
  }
  addrinfo hints = {};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE;
  addrinfo* found = nullptr;
  const int rc = ::getaddrinfo(host.empty() ? nullptr : host.c_str(), port.c_str(), &hints, &found);
  if (rc != 0) {
    return MakeError(ErrorCode::kUnavailable, "cannot listen on " + listen + ": the host '" + host +
                                                  "' does not resolve (" + ::gai_strerror(rc) +
                                                  ")");
  }
  Status status = Status::Ok();
  for (addrinfo* a = found; a != nullptr && status.ok(); a = a->ai_next) {
    const int fd = ::socket(a->ai_family, a->ai_socktype, a->ai_protocol);
    if (fd < 0) continue;
    const int one = 1;
    ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
    if (::bind(fd, a->ai_addr, a->ai_addrlen) != 0) {
      const int err = errno;
      if (err == EADDRINUSE) {
        status = MakeError(ErrorCode::kUnavailable,
                           "cannot listen on " + listen + ": port " + port +
                               " is already in use (another hposed running?); stop it or choose "
                               "another address with --listen HOST:PORT");
      } else if (err == EADDRNOTAVAIL) {
        status = MakeError(ErrorCode::kUnavailable, "cannot listen on " + listen + ": '" + host +
                                                        "' is not an address of this machine");
      } else if (err == EACCES) {
        status = MakeError(ErrorCode::kUnavailable, "cannot listen on " + listen +
                                                        ": permission denied (ports below 1024 "
                                                        "need privileges)");
      }
    }
    ::close(fd);
  }
  ::freeaddrinfo(found);
  return status;
}

}  // namespace hpose::server
