#include "server/publish_order.h"

#include <algorithm>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace hpose::server {
namespace {

using Order = PublishOrder<std::string>;

TEST(PublishOrderTest, TicketsCountUpInArrivalOrder) {
  Order order(Order::Policy::kInOrder);
  EXPECT_EQ(order.NextTicket(), 0u);
  EXPECT_EQ(order.NextTicket(), 1u);
  EXPECT_EQ(order.NextTicket(), 2u);
}

TEST(PublishOrderTest, InOrderHoldsALaterResultUntilTheEarlierOneIsDone) {
  Order order(Order::Policy::kInOrder);
  const std::uint64_t a = order.NextTicket(), b = order.NextTicket(), c = order.NextTicket();
  std::vector<std::string> out;
  EXPECT_EQ(order.Done(b, "b", &out), 0);
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(order.waiting(), 1u);
  EXPECT_EQ(order.Done(c, "c", &out), 0);
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(order.Done(a, "a", &out), 0);
  EXPECT_EQ(out, (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_EQ(order.waiting(), 0u);
}

TEST(PublishOrderTest, NewestOnlyPublishesAtOnceAndDropsWhatANewerResultOvertook) {
  Order order(Order::Policy::kNewestOnly);
  const std::uint64_t a = order.NextTicket(), b = order.NextTicket(), c = order.NextTicket();
  std::vector<std::string> out;
  EXPECT_EQ(order.Done(b, "b", &out), 0);
  EXPECT_EQ(out, (std::vector<std::string>{"b"}));
  EXPECT_EQ(order.Done(a, "a", &out), 1);  // older than the published b.
  EXPECT_EQ(order.Done(c, "c", &out), 0);
  EXPECT_EQ(out, (std::vector<std::string>{"b", "c"}));
}

// Any completion order: kInOrder publishes every result exactly once in ticket order;
// kNewestOnly publishes an increasing subsequence and drops the rest, nothing lost silently.
TEST(PublishOrderTest, AnyCompletionOrder) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 50; ++trial) {
    const int n = 1 + trial;
    for (const auto policy : {Order::Policy::kInOrder, Order::Policy::kNewestOnly}) {
      Order order(policy);
      std::vector<std::uint64_t> tickets(n);
      for (auto& t : tickets) t = order.NextTicket();
      // Completion order: shuffled within windows of 3 (three estimation threads).
      for (int i = 0; i + 1 < n; i += 3) {
        std::shuffle(tickets.begin() + i, tickets.begin() + std::min(n, i + 3), rng);
      }
      std::vector<std::string> out;
      int superseded = 0;
      for (const std::uint64_t t : tickets) {
        superseded += order.Done(t, std::to_string(t), &out);
      }
      std::vector<int> published;
      for (const std::string& s : out) published.push_back(std::stoi(s));
      EXPECT_TRUE(std::is_sorted(published.begin(), published.end()));
      EXPECT_EQ(std::adjacent_find(published.begin(), published.end()), published.end());
      EXPECT_EQ(static_cast<int>(published.size()) + superseded, n);
      EXPECT_EQ(published.back(), n - 1);  // the newest frame is always published.
      if (policy == Order::Policy::kInOrder) {
        EXPECT_EQ(superseded, 0);
        EXPECT_EQ(order.waiting(), 0u);
      }
    }
  }
}

}  // namespace
}  // namespace hpose::server
