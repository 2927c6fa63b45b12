#ifndef HPOSE_SERVER_TCP_LISTEN_H_
#define HPOSE_SERVER_TCP_LISTEN_H_

#include <string>
#include <vector>

#include "core/common/status.h"

namespace hpose::server {

// Listening sockets on every address of one host, all on one port.
struct TcpListeners {
  std::vector<int> fds;  // non-blocking, close-on-exec; the caller closes them.
  int port = 0;          // the port bound (the one picked, when 0 was asked for).
};

// Binds and listens on PORT at every address HOST resolves to ("localhost" is often both
// 127.0.0.1 and ::1; an IPv6 wildcard also takes IPv4), with `backlog` connections queued by
// the kernel. HOST may be a name or a numeric address, IPv6 with or without brackets. Port 0
// picks a free port, the same for every address. kUnavailable naming the reason (the host does
// not resolve, "Address already in use", ...) when no address can be bound.
Result<TcpListeners> ListenTcp(const std::string& host, int port, int backlog);

}  // namespace hpose::server

#endif  // HPOSE_SERVER_TCP_LISTEN_H_
