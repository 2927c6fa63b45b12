#include "core/common/task_pool.h"

#include <atomic>
#include <set>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

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
  EXPECT_EQ(TaskPool::Resolve(3), 3);
}

}  // namespace
}  // namespace hpose
