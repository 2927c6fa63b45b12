#ifndef HPOSE_BENCH_BENCH_THREADS_H_
#define HPOSE_BENCH_BENCH_THREADS_H_

// Shared by the benchmarks that estimate many independent frames: a pool of threads that takes
// them one at a time.

#include <cstddef>
#include <functional>

namespace hpose::bench {

// Does items 0 .. count-1 on `threads` threads (at least one), each thread taking the next item
// not yet taken. On each thread `make_work()` is called once and gives the function that does an
// item there, so that it can hold that thread's own state (estimators are used by one thread at
// a time). Prints "\r  NOUN n/count" to stderr every 20 items and after the last, then a newline.
void ForEachOnThreads(int threads, size_t count, const char* noun,
                      const std::function<std::function<void(size_t)>()>& make_work);

}  // namespace hpose::bench

#endif  // HPOSE_BENCH_BENCH_THREADS_H_
