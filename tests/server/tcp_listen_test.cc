#include "server/tcp_listen.h"

#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <string>

namespace hpose::server {
namespace {

void CloseAll(const TcpListeners& listeners) {
  for (int fd : listeners.fds) close(fd);
}

// Connects to 127.0.0.1:port; true if the connection is taken (by the backlog).
bool ConnectsOnIpv4(int port) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<uint16_t>(port));
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  const bool ok = connect(fd, reinterpret_cast<sockaddr*>(&to), sizeof(to)) == 0;
  close(fd);
  return ok;
}

TEST(TcpListenTest, PortZeroPicksOnePortForEveryAddress) {
  Result<TcpListeners> bound = ListenTcp("localhost", 0, 16);
  ASSERT_TRUE(bound.ok()) << bound.error().message;
  ASSERT_FALSE(bound->fds.empty());
  EXPECT_GT(bound->port, 0);
  for (int fd : bound->fds) {
    sockaddr_storage address{};
    socklen_t len = sizeof(address);
    ASSERT_EQ(getsockname(fd, reinterpret_cast<sockaddr*>(&address), &len), 0);
    const int port =
        ntohs(address.ss_family == AF_INET6 ? reinterpret_cast<sockaddr_in6*>(&address)->sin6_port
                                            : reinterpret_cast<sockaddr_in*>(&address)->sin_port);
    EXPECT_EQ(port, bound->port);
  }
  EXPECT_TRUE(ConnectsOnIpv4(bound->port));
  CloseAll(*bound);
}

TEST(TcpListenTest, NumericAddressesWithAndWithoutBrackets) {
  Result<TcpListeners> v4 = ListenTcp("127.0.0.1", 0, 16);
  ASSERT_TRUE(v4.ok()) << v4.error().message;
  EXPECT_EQ(v4->fds.size(), 1u);
  EXPECT_TRUE(ConnectsOnIpv4(v4->port));
  CloseAll(*v4);
  // An IPv6 wildcard is dual-stack: IPv4 clients reach it too.
  Result<TcpListeners> any = ListenTcp("[::]", 0, 16);
  if (!any.ok()) GTEST_SKIP() << "no IPv6 on this machine: " << any.error().message;
  EXPECT_TRUE(ConnectsOnIpv4(any->port));
  CloseAll(*any);
}

TEST(TcpListenTest, ErrorsNameTheReason) {
  Result<TcpListeners> first = ListenTcp("127.0.0.1", 0, 16);
  ASSERT_TRUE(first.ok());
  Result<TcpListeners> again = ListenTcp("127.0.0.1", first->port, 16);
  ASSERT_FALSE(again.ok());
  EXPECT_EQ(again.error().code, ErrorCode::kUnavailable);
  EXPECT_NE(again.error().message.find("in use"), std::string::npos) << again.error().message;
  CloseAll(*first);

  Result<TcpListeners> unknown = ListenTcp("no-such-host.invalid", 0, 16);
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.error().message.find("cannot resolve 'no-such-host.invalid'"),
            std::string::npos)
      << unknown.error().message;

  Result<TcpListeners> foreign = ListenTcp("192.0.2.1", 0, 16);  // TEST-NET-1, not ours.
  ASSERT_FALSE(foreign.ok());
  EXPECT_NE(foreign.error().message.find("assign"), std::string::npos) << foreign.error().message;
}

}  // namespace
}  // namespace hpose::server
