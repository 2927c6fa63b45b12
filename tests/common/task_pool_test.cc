#include "core/common/task_pool.h"

#include <atomic>
#include <set>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#if defined(__linux__)
#include <sched.h>
#endif

namespace hpose {
namespace {

TEST(TaskPoolTest, RunsEveryItemExactlyOnce) {
  for (int threads : {1, 2, 4}) {
    TaskPool pool(threads);
    EXPECT_EQ(pool.threads(), threads);
    for (int n : {0, 1, 3, 100}) {
      std::vector<std::atomic<int>> runs(static_cast<size_t>(n));
      pool.ParallelFor(n, [&](int i) { runs[static_cast<size_t>(i)]++; });
      for (int i = 0; i < n; ++i) EXPECT_EQ(runs[static_cast<size_t>(i)].load(), 1) << i;
    }
  }
}

TEST(TaskPoolTest, UsesMoreThanOneThreadWhenItemsWait) {
  TaskPool pool(2);
  std::mutex mu;
  std::set<std::thread::id> ids;
  std::atomic<int> arrived{0};
  // Each item waits (bounded) until both have started: only possible on two threads.
  pool.ParallelFor(2, [&](int) {
    {
      std::lock_guard<std::mutex> lock(mu);
      ids.insert(std::this_thread::get_id());
    }
    ++arrived;
    for (int spin = 0; spin < 2000 && arrived.load() < 2; ++spin) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  });
  EXPECT_EQ(ids.size(), 2u);
}

TEST(TaskPoolTest, ConcurrentLoopsTakeTurns) {
  TaskPool pool(3);
  std::atomic<int> total{0};
  std::vector<std::thread> callers;
  for (int c = 0; c < 4; ++c) {
    callers.emplace_back([&] {
      for (int r = 0; r < 20; ++r) pool.ParallelFor(10, [&](int) { ++total; });
    });
  }
  for (std::thread& t : callers) t.join();
  EXPECT_EQ(total.load(), 4 * 20 * 10);
}

TEST(TaskPoolTest, ResolveZeroMeansOnePerCore) {
  EXPECT_GE(TaskPool::Resolve(0), 1);
  EXPECT_EQ(TaskPool::Resolve(0), TaskPool::UsableCores());
  EXPECT_EQ(TaskPool::Resolve(3), 3);
}

#if defined(__linux__)
// One core per usable core counts the cores the thread may run on (as taskset restricts them),
// not every core of the machine: a thread pinned to one core resolves 0 to one thread.
TEST(TaskPoolTest, UsableCoresFollowTheAffinity) {
  cpu_set_t all;
  CPU_ZERO(&all);
  ASSERT_EQ(sched_getaffinity(0, sizeof(all), &all), 0);
  EXPECT_EQ(TaskPool::UsableCores(), CPU_COUNT(&all));
  int first = 0;
  while (!CPU_ISSET(first, &all)) ++first;
  int pinned = -1;
  std::thread t([&] {
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(first, &one);
    if (sched_setaffinity(0, sizeof(one), &one) == 0) pinned = TaskPool::Resolve(0);
  });
  t.join();
  EXPECT_EQ(pinned, 1);
}
#endif

}  // namespace
}  // namespace hpose
