#include "server/pipeline_stats.h"

#include <gtest/gtest.h>

namespace hpose::server {
namespace {

using Clock = PipelineStats::Clock;

TEST(PipelineStatsTest, RatesOverTheWindowAndLatencyQuantiles) {
  PipelineStats stats;
  const Clock::time_point t0 = Clock::now();
  for (int i = 0; i <= 20; ++i) {  // 10 Hz for 2 s; latency 10..210 ms.
    const Clock::time_point t = t0 + std::chrono::milliseconds(100 * i);
    stats.RecordInput(t);
    stats.RecordPublish(t, 0.010 * (i + 1));
  }
  const StatsSnapshot s = stats.Snapshot(t0 + std::chrono::milliseconds(2050));
  EXPECT_NEAR(s.input_rate_hz, 10.0, 1e-6);
  EXPECT_NEAR(s.estimate_rate_hz, 10.0, 1e-6);
  EXPECT_EQ(s.latency_samples, 21u);
  EXPECT_NEAR(s.latency_median_s, 0.110, 1e-9);
  EXPECT_NEAR(s.latency_p99_s, 0.210, 1e-9);
  EXPECT_NEAR(s.latency_last_s, 0.210, 1e-9);
}

TEST(PipelineStatsTest, RatesDecayWhenFramesStop) {
  PipelineStats stats;
  const Clock::time_point t0 = Clock::now();
  for (int i = 0; i < 5; ++i) stats.RecordInput(t0 + std::chrono::milliseconds(200 * i));
  EXPECT_GT(stats.Snapshot(t0 + std::chrono::seconds(1)).input_rate_hz, 0.0);
  EXPECT_EQ(stats.Snapshot(t0 + std::chrono::seconds(10)).input_rate_hz, 0.0);
  EXPECT_EQ(PipelineStats().Snapshot(t0).latency_samples, 0u);
}

}  // namespace
}  // namespace hpose::server

#include "server/pose_pipeline.h"

namespace hpose::server {
namespace {

TEST(DescribeStalenessTest, NamesWhyAnEstimateIsStale) {
  std::string reason;
  EXPECT_FALSE(
      DescribeStaleness(SourceState::kRunning, "", 0.5, 2.0, "source", "estimate", &reason));
  EXPECT_TRUE(reason.empty());
  EXPECT_TRUE(DescribeStaleness(SourceState::kRunning, "", 2.5, 2.0, "stereo source",
                                "stereo estimate", &reason));
  EXPECT_EQ(reason, "no newer stereo estimate for 2.50 s");
  EXPECT_TRUE(DescribeStaleness(SourceState::kReconnecting, "device unplugged", 0.1, 2.0, "source",
                                "estimate", &reason));
  EXPECT_EQ(reason, "source reconnecting: device unplugged");
}

}  // namespace
}  // namespace hpose::server
