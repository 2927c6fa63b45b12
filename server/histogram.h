#ifndef HPOSE_SERVER_HISTOGRAM_H_
#define HPOSE_SERVER_HISTOGRAM_H_

#include <cstdint>
#include <mutex>
#include <vector>

namespace hpose::server {

// A Prometheus-style histogram of durations or sizes: counts of observations at or below each
// upper bound, their sum and their count. Thread-safe.
class Histogram final {
 public:
  struct Snapshot {
    std::vector<double> upper_bounds;       // ascending, without +Inf.
    std::vector<std::uint64_t> cumulative;  // observations <= upper_bounds[i].
    std::uint64_t count = 0;                // every observation (the +Inf bucket).
    double sum = 0.0;
  };

  // `upper_bounds` must be ascending and finite (asserted).
  explicit Histogram(std::vector<double> upper_bounds);

  // NaN observations are ignored.
  void Observe(double value);
  Snapshot Read() const;

  // Bounds from `start` multiplied by `factor`, `count` of them (e.g. 1 ms .. 8 s).
  static std::vector<double> ExponentialBounds(double start, double factor, int count);

 private:
  mutable std::mutex mu_;
  std::vector<double> upper_bounds_;
  std::vector<std::uint64_t> counts_;  // per bucket (not cumulative); last = above every bound.
  double sum_ = 0.0;
};

}  // namespace hpose::server

#endif  // HPOSE_SERVER_HISTOGRAM_H_
