#include "bench/bench_threads.h"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <thread>
#include <vector>

namespace hpose::bench {

void ForEachOnThreads(int threads, size_t count, const char* noun,
                      const std::function<std::function<void(size_t)>()>& make_work) {
  std::atomic<size_t> next{0}, done{0};
  auto worker = [&]() {
    const std::function<void(size_t)> work = make_work();
    for (size_t i = next++; i < count; i = next++) {
      work(i);
      const size_t n = ++done;
      if (n % 20 == 0 || n == count) std::fprintf(stderr, "\r  %s %zu/%zu", noun, n, count);
    }
  };
  std::vector<std::thread> pool;
  for (int k = 0; k < std::max(1, threads); ++k) pool.emplace_back(worker);
  for (std::thread& t : pool) t.join();
  std::fprintf(stderr, "\n");
}

}  // namespace hpose::bench
