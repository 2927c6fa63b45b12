#include "server/tcp_listener.h"

#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <future>
#include <memory>
#include <string>
#include <vector>

namespace hpose::server {
namespace {

// Connects to 127.0.0.1:port; the socket (-1 when refused). The caller closes it.
int ConnectOnIpv4(int port) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<uint16_t>(port));
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (connect(fd, reinterpret_cast<sockaddr*>(&to), sizeof(to)) != 0) {
    close(fd);
    return -1;
  }
  return fd;
}

bool ConnectsOnIpv4(int port) {
  const int fd = ConnectOnIpv4(port);
  if (fd >= 0) close(fd);
  return fd >= 0;
}

TEST(TcpListenerTest, PortZeroPicksOnePortForEveryAddress) {
  Result<std::unique_ptr<TcpListener>> bound = TcpListener::Listen("localhost", 0, 16);
  ASSERT_TRUE(bound.ok()) << bound.error().message;
  const TcpListener& listener = **bound;
  ASSERT_FALSE(listener.fds().empty());
  EXPECT_GT(listener.port(), 0);
  for (int fd : listener.fds()) {
    sockaddr_storage address{};
    socklen_t len = sizeof(address);
    ASSERT_EQ(getsockname(fd, reinterpret_cast<sockaddr*>(&address), &len), 0);
    const int port =
        ntohs(address.ss_family == AF_INET6 ? reinterpret_cast<sockaddr_in6*>(&address)->sin6_port
                                            : reinterpret_cast<sockaddr_in*>(&address)->sin_port);
    EXPECT_EQ(port, listener.port());
  }
  EXPECT_TRUE(ConnectsOnIpv4(listener.port()));
}

TEST(TcpListenerTest, NumericAddressesWithAndWithoutBrackets) {
  Result<std::unique_ptr<TcpListener>> v4 = TcpListener::Listen("127.0.0.1", 0, 16);
  ASSERT_TRUE(v4.ok()) << v4.error().message;
  EXPECT_EQ((*v4)->fds().size(), 1u);
  EXPECT_TRUE(ConnectsOnIpv4((*v4)->port()));
  // An IPv6 wildcard is dual-stack: IPv4 clients reach it too.
  Result<std::unique_ptr<TcpListener>> any = TcpListener::Listen("[::]", 0, 16);
  if (!any.ok()) GTEST_SKIP() << "no IPv6 on this machine: " << any.error().message;
  EXPECT_TRUE(ConnectsOnIpv4((*any)->port()));
}

TEST(TcpListenerTest, ErrorsSayWhyInASentence) {
  Result<std::unique_ptr<TcpListener>> first = TcpListener::Listen("127.0.0.1", 0, 16);
  ASSERT_TRUE(first.ok());
  const int port = (*first)->port();
  Result<std::unique_ptr<TcpListener>> again = TcpListener::Listen("127.0.0.1", port, 16);
  ASSERT_FALSE(again.ok());
  EXPECT_EQ(again.error().code, ErrorCode::kUnavailable);
  EXPECT_EQ(again.error().message,
            "port " + std::to_string(port) + " is already in use (another hposed running?)");
  first->reset();
  // Closed, the port is free again.
  EXPECT_TRUE(TcpListener::Listen("127.0.0.1", port, 16).ok());

  Result<std::unique_ptr<TcpListener>> unknown = TcpListener::Listen("no-such-host.invalid", 0, 16);
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.error().code, ErrorCode::kUnavailable);
  EXPECT_EQ(unknown.error().message.rfind("the host 'no-such-host.invalid' does not resolve (", 0),
            0u)
      << unknown.error().message;

  Result<std::unique_ptr<TcpListener>> foreign =
      TcpListener::Listen("192.0.2.1", 0, 16);  // TEST-NET-1, not ours.
  ASSERT_FALSE(foreign.ok());
  EXPECT_EQ(foreign.error().message, "'192.0.2.1' is not an address of this machine");

  if (geteuid() != 0) {
    Result<std::unique_ptr<TcpListener>> privileged = TcpListener::Listen("127.0.0.1", 1, 16);
    ASSERT_FALSE(privileged.ok());
    EXPECT_NE(privileged.error().message.find("permission denied"), std::string::npos)
        << privileged.error().message;
  }
}

TEST(TcpListenerTest, WaitTellsWhichSocketHasAConnectionAndWakeEndsIt) {
  Result<std::unique_ptr<TcpListener>> bound = TcpListener::Listen("127.0.0.1", 0, 16);
  ASSERT_TRUE(bound.ok()) << bound.error().message;
  TcpListener* listener = bound->get();
  const int client = ConnectOnIpv4(listener->port());
  ASSERT_GE(client, 0);
  std::vector<int> ready;
  ASSERT_TRUE(listener->Wait(&ready));
  EXPECT_EQ(ready, listener->fds());
  const int served = accept(ready.front(), nullptr, nullptr);
  EXPECT_GE(served, 0);
  close(served);
  close(client);

  // Nothing to accept: Wait blocks until woken, and returns false from then on.
  std::future<bool> waiting =
      std::async(std::launch::async, [listener, &ready] { return listener->Wait(&ready); });
  EXPECT_EQ(waiting.wait_for(std::chrono::milliseconds(100)), std::future_status::timeout);
  listener->Wake();
  ASSERT_EQ(waiting.wait_for(std::chrono::seconds(5)), std::future_status::ready);
  EXPECT_FALSE(waiting.get());
  EXPECT_FALSE(listener->Wait(&ready));
  EXPECT_TRUE(ready.empty());
}

TEST(ParseHostPortTest, HostAndPortOrASentence) {
  Result<HostPort> v4 = ParseHostPort("127.0.0.1:50051");
  ASSERT_TRUE(v4.ok());
  EXPECT_EQ(v4->host, "127.0.0.1");
  EXPECT_EQ(v4->port, 50051);
  Result<HostPort> v6 = ParseHostPort("[::1]:0");
  ASSERT_TRUE(v6.ok());
  EXPECT_EQ(v6->host, "::1");
  EXPECT_EQ(v6->port, 0);
  EXPECT_EQ(ParseHostPort("localhost:65535")->port, 65535);
  for (const char* bad : {"", "localhost", "localhost:", ":50051", "[]:80", "host:65536", "host:-1",
                          "host:8o80", "host:999999999999999999999999999999"}) {
    Result<HostPort> parsed = ParseHostPort(bad);
    ASSERT_FALSE(parsed.ok()) << bad;
    EXPECT_EQ(parsed.error().code, ErrorCode::kInvalidArgument);
    EXPECT_EQ(parsed.error().message,
              std::string("expected HOST:PORT with a port of 0-65535, got '") + bad + "'");
  }
}

}  // namespace
}  // namespace hpose::server
