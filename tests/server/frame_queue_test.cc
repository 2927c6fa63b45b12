#include "server/frame_queue.h"

#include <gtest/gtest.h>

#include <thread>

namespace hpose::server {
namespace {

Frame WithSequence(std::uint64_t s) {
  Frame f;
  f.sequence = s;
  return f;
}

TEST(FrameQueueTest, DropsTheOldestWhenFullAndCountsIt) {
  FrameQueue q(2);
  EXPECT_EQ(q.Push(WithSequence(1), false), 0u);
  EXPECT_EQ(q.Push(WithSequence(2), false), 0u);
  EXPECT_EQ(q.Push(WithSequence(3), false), 1u);
  EXPECT_EQ(q.size(), 2u);
  EXPECT_EQ(q.Pop(std::chrono::milliseconds(0))->sequence, 2u);
  EXPECT_EQ(q.Pop(std::chrono::milliseconds(0))->sequence, 3u);
  EXPECT_FALSE(q.Pop(std::chrono::milliseconds(1)).has_value());
}

TEST(FrameQueueTest, BlockingPushWaitsForRoomAndCloseWakesEveryone) {
  FrameQueue q(1);
  q.Push(WithSequence(1), true);
  std::thread producer([&] { EXPECT_EQ(q.Push(WithSequence(2), true), 0u); });
  auto first = q.Pop(std::chrono::seconds(5));
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(first->sequence, 1u);
  auto second = q.Pop(std::chrono::seconds(5));
  producer.join();
  ASSERT_TRUE(second.has_value());
  EXPECT_EQ(second->sequence, 2u);  // nothing was dropped.

  std::thread waiter([&] { EXPECT_FALSE(q.Pop(std::chrono::seconds(30)).has_value()); });
  q.Close();
  waiter.join();
  EXPECT_EQ(q.Push(WithSequence(3), true), 0u);  // closed: discarded, does not block.
}

}  // namespace
}  // namespace hpose::server
