#ifndef HPOSE_SERVER_PIPELINE_STATS_H_
#define HPOSE_SERVER_PIPELINE_STATS_H_

#include <chrono>
#include <cstdint>
#include <deque>

namespace hpose::server {

// A steady-clock span in seconds, as the pipelines report durations.
inline double Seconds(std::chrono::steady_clock::duration d) {
  return std::chrono::duration<double>(d).count();
}

// Rates and latencies as GetStatus reports them.
struct StatsSnapshot {
  double input_rate_hz = 0.0;     // frames arriving, over the last few seconds.
  double estimate_rate_hz = 0.0;  // estimates published, same window.
  std::uint32_t latency_samples = 0;
  double latency_median_s = 0.0;  // frame arrival -> estimate published.
  double latency_p99_s = 0.0;
  double latency_last_s = 0.0;
};

// Sliding-window input and publication rates and a window of recent latencies, shared by the
// depth and stereo pipelines. Not thread-safe: the owning pipeline's mutex guards it.
class PipelineStats {
 public:
  using Clock = std::chrono::steady_clock;

  void RecordInput(Clock::time_point t);
  void RecordPublish(Clock::time_point t, double latency_s);
  // Rates decay to zero when nothing arrived within the window before `now`.
  StatsSnapshot Snapshot(Clock::time_point now) const;

 private:
  std::deque<Clock::time_point> input_times_;
  std::deque<Clock::time_point> publish_times_;
  std::deque<double> latencies_;
};

}  // namespace hpose::server

#endif  // HPOSE_SERVER_PIPELINE_STATS_H_
