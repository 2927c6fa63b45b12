#include "server/stream_limiter.h"

#include <gtest/gtest.h>

#include <optional>
#include <vector>

namespace hpose::server {
namespace {

TEST(StreamLimiterTest, PeerHostDropsThePortAndBrackets) {
  EXPECT_EQ(PeerHost("ipv4:10.0.0.5:40312"), "10.0.0.5");
  EXPECT_EQ(PeerHost("ipv6:[::1]:40312"), "::1");
  EXPECT_EQ(PeerHost("ipv6:[fe80::1:2]:9"), "fe80::1:2");
  EXPECT_EQ(PeerHost("ipv6:[::ffff:192.168.1.7]:9"), "192.168.1.7");
  EXPECT_EQ(PeerHost("unix:/run/hposed.sock"), "unix:/run/hposed.sock");
}

TEST(StreamLimiterTest, ClientIsTheTokenElseTheAddress) {
  // Two connections of one host are one client; a token is one client from any address.
  EXPECT_EQ(ClientKey(false, "", "ipv4:10.0.0.5:1"), ClientKey(false, "", "ipv4:10.0.0.5:2"));
  EXPECT_NE(ClientKey(false, "", "ipv4:10.0.0.5:1"), ClientKey(false, "", "ipv4:10.0.0.6:1"));
  EXPECT_EQ(ClientKey(true, "Bearer a", "ipv4:10.0.0.5:1"),
            ClientKey(true, "Bearer a", "ipv4:10.0.0.9:7"));
  EXPECT_NE(ClientKey(true, "Bearer a", "ipv4:10.0.0.5:1"),
            ClientKey(true, "Bearer b", "ipv4:10.0.0.5:1"));
  // A token that looks like an address is still not that address.
  EXPECT_NE(ClientKey(true, "10.0.0.5", "ipv4:10.0.0.5:1"),
            ClientKey(false, "", "ipv4:10.0.0.5:1"));
}

TEST(StreamLimiterTest, EachClientHasItsOwnLimit) {
  StreamLimiter limiter(2);
  std::vector<StreamLimiter::Slot> a;
  a.push_back(limiter.TryOpen("a"));
  a.push_back(limiter.TryOpen("a"));
  EXPECT_TRUE(a[0].admitted());
  EXPECT_TRUE(a[1].admitted());
  EXPECT_EQ(limiter.open("a"), 2);
  EXPECT_FALSE(limiter.TryOpen("a").admitted());  // the third of "a".
  EXPECT_EQ(limiter.rejected(), 1u);
  EXPECT_EQ(limiter.open("a"), 2);  // a refusal holds nothing.
  {
    StreamLimiter::Slot b = limiter.TryOpen("b");
    EXPECT_TRUE(b.admitted());
    EXPECT_EQ(limiter.open("b"), 1);
  }
  EXPECT_EQ(limiter.open("b"), 0);  // given back when the slot ends.
  a.pop_back();
  EXPECT_EQ(limiter.open("a"), 1);
  std::optional<StreamLimiter::Slot> again(limiter.TryOpen("a"));
  EXPECT_TRUE(again->admitted());
  StreamLimiter::Slot moved(std::move(*again));  // moving hands the place over, once.
  again.reset();
  EXPECT_EQ(limiter.open("a"), 2);
}

}  // namespace
}  // namespace hpose::server
