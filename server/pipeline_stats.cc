#include "server/pipeline_stats.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/common/quantile.h"

namespace hpose::server {
namespace {

constexpr size_t kLatencyWindow = 256;  // latencies kept for the median and p99.
constexpr double kRateWindowS = 3.0;    // rates are measured over this many seconds.

void Trim(std::deque<PipelineStats::Clock::time_point>* times,
          PipelineStats::Clock::time_point now) {
  while (!times->empty() && Seconds(now - times->front()) > kRateWindowS) times->pop_front();
}

double RecentRate(const std::deque<PipelineStats::Clock::time_point>& times,
                  PipelineStats::Clock::time_point now) {
  if (times.size() < 2 || Seconds(now - times.back()) >= kRateWindowS) return 0.0;
  const double span = Seconds(times.back() - times.front());
  return span > 0.0 ? (times.size() - 1) / span : 0.0;
}

}  // namespace

void PipelineStats::RecordInput(Clock::time_point t) {
  input_times_.push_back(t);
  Trim(&input_times_, t);
}

void PipelineStats::RecordPublish(Clock::time_point t, double latency_s) {
  publish_times_.push_back(t);
  Trim(&publish_times_, t);
  latencies_.push_back(latency_s);
  if (latencies_.size() > kLatencyWindow) latencies_.pop_front();
}

StatsSnapshot PipelineStats::Snapshot(Clock::time_point now) const {
  StatsSnapshot s;
  s.input_rate_hz = RecentRate(input_times_, now);
  s.estimate_rate_hz = RecentRate(publish_times_, now);
  std::vector<double> lat(latencies_.begin(), latencies_.end());
  s.latency_samples = static_cast<std::uint32_t>(lat.size());
  s.latency_last_s = lat.empty() ? 0.0 : lat.back();
  std::sort(lat.begin(), lat.end());
  s.latency_median_s = QuantileOfSorted(lat, 0.5);
  s.latency_p99_s = QuantileOfSorted(lat, 0.99);
  return s;
}

}  // namespace hpose::server
