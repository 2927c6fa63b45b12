#include "server/elastic_task_queue.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>

namespace hpose::server {
namespace {

// A gate that jobs wait on until the test opens it.
struct Gate {
  std::mutex mutex;
  std::condition_variable cv;
  bool open = false;
  int waiting = 0;
  void Wait() {
    std::unique_lock<std::mutex> lock(mutex);
    ++waiting;
    cv.notify_all();
    cv.wait(lock, [this] { return open; });
  }
  // Waits (at most a minute, so a broken queue fails instead of hanging) for n waiters.
  bool AwaitWaiters(int n) {
    std::unique_lock<std::mutex> lock(mutex);
    return cv.wait_for(lock, std::chrono::seconds(60), [&] { return waiting >= n; });
  }
  void Open() {
    {
      const std::lock_guard<std::mutex> lock(mutex);
      open = true;
    }
    cv.notify_all();
  }
};

TEST(ElasticTaskQueueTest, BlockedJobsDoNotHoldUpLaterOnes) {
  ElasticTaskQueue queue(2, 32);
  EXPECT_EQ(queue.threads(), 2);
  Gate gate;
  // Twenty jobs that hold their threads (as connections that never finish their request)...
  for (int i = 0; i < 20; ++i) queue.Enqueue([&gate] { gate.Wait(); });
  ASSERT_TRUE(gate.AwaitWaiters(20)) << "the blocked jobs did not all start";
  // ...and one more still runs while they wait: a fixed pool of 2 would never get to it.
  std::atomic<bool> ran{false};
  Gate done;
  queue.Enqueue([&] {
    ran = true;
    done.Wait();
  });
  ASSERT_TRUE(done.AwaitWaiters(1));
  EXPECT_TRUE(ran);
  EXPECT_GE(queue.threads(), 21);
  EXPECT_LE(queue.threads(), 32);
  gate.Open();
  done.Open();
  queue.Shutdown();
  EXPECT_EQ(queue.threads(), 0);
}

TEST(ElasticTaskQueueTest, BeyondItsLimitJobsWaitAndAllRun) {
  ElasticTaskQueue queue(1, 3);
  Gate gate;
  std::atomic<int> finished{0};
  for (int i = 0; i < 10; ++i) {
    queue.Enqueue([&] {
      gate.Wait();
      ++finished;
    });
  }
  ASSERT_TRUE(gate.AwaitWaiters(3));
  EXPECT_EQ(queue.threads(), 3);  // never more than the limit.
  {
    const std::lock_guard<std::mutex> lock(gate.mutex);
    EXPECT_EQ(gate.waiting, 3);  // the other seven wait for a thread.
  }
  gate.Open();
  queue.Shutdown();  // runs what was queued, then joins.
  EXPECT_EQ(finished, 10);
  queue.Enqueue([&] { ++finished; });  // dropped after shutdown.
  EXPECT_EQ(finished, 10);
}

TEST(ElasticTaskQueueTest, IdleThreadsAreReusedNotMultiplied) {
  ElasticTaskQueue queue(2, 64);
  for (int i = 0; i < 200; ++i) {
    std::mutex m;
    std::condition_variable cv;
    bool done = false;
    queue.Enqueue([&] {
      const std::lock_guard<std::mutex> lock(m);
      done = true;
      cv.notify_all();
    });
    std::unique_lock<std::mutex> lock(m);
    ASSERT_TRUE(cv.wait_for(lock, std::chrono::seconds(60), [&] { return done; }));
  }
  // One job at a time runs on the threads there are: a new one starts only when a job comes
  // while every thread is between its last job and waiting again, which is rare.
  EXPECT_LE(queue.threads(), 16);
}

}  // namespace
}  // namespace hpose::server
