#ifndef HPOSE_SERVER_TCP_LISTENER_H_
#define HPOSE_SERVER_TCP_LISTENER_H_

#include <memory>
#include <string>
#include <vector>

#include "core/common/status.h"

namespace hpose::server {

// A listen address as written in a configuration: "HOST:PORT", "[V6]:PORT".
struct HostPort {
  std::string host;  // a name or a numeric address, IPv6 without its brackets.
  int port = 0;      // 0-65535; 0 picks a free port.
};

// kInvalidArgument naming `listen` when it is not HOST:PORT with a host and a decimal port.
Result<HostPort> ParseHostPort(const std::string& listen);

// Listening sockets on every address of one host, all on one port, and a way to wake the
// thread that waits on them.
class TcpListener {
 public:
  // Binds and listens on PORT at every address HOST resolves to ("localhost" is often both
  // 127.0.0.1 and ::1; an IPv6 wildcard also takes IPv4), with `backlog` connections queued by
  // the kernel. Port 0 picks a free port, the same for every address. kUnavailable with a
  // sentence naming the reason when no address can be bound: the host does not resolve, the
  // port is already in use, the host is not an address of this machine, the port needs
  // privileges.
  static Result<std::unique_ptr<TcpListener>> Listen(const std::string& host, int port,
                                                     int backlog);
  ~TcpListener();  // closes the sockets.
  TcpListener(const TcpListener&) = delete;
  TcpListener& operator=(const TcpListener&) = delete;

  int port() const { return port_; }
  // The listening sockets (non-blocking, close-on-exec).
  const std::vector<int>& fds() const { return fds_; }

  // Waits until a socket has a connection to accept, and puts those sockets in `ready`: true.
  // False once Wake() was called (or waiting failed: errno tells).
  bool Wait(std::vector<int>* ready);
  // Makes Wait return false, now and from then on. Any thread; idempotent.
  void Wake();

 private:
  TcpListener(std::vector<int> fds, int port, int wake_read, int wake_write);

  const std::vector<int> fds_;
  const int port_;
  const int wake_read_;  // a pipe: a byte written wakes Wait.
  const int wake_write_;
};

}  // namespace hpose::server

#endif  // HPOSE_SERVER_TCP_LISTENER_H_
