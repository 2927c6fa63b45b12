// DaemonMetrics' /metrics text against a parser of the Prometheus text exposition format (0.0.4)
// written from its specification: comment lines, sample lines, label syntax, one TYPE per
// family before its samples, histogram buckets cumulative with +Inf equal to _count.
#include "server/metrics.h"

#include <sys/resource.h>
#include <unistd.h>

#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace hpose::server {
namespace {

struct Sample {
  std::string name;
  std::map<std::string, std::string> labels;
  double value = 0.0;
};

struct Exposition {
  std::map<std::string, std::string> types;  // family -> counter | gauge | histogram | ...
  std::vector<Sample> samples;
};

bool IsNameStart(char c) {
  return std::isalpha(static_cast<unsigned char>(c)) || c == '_' || c == ':';
}
bool IsNameChar(char c) { return IsNameStart(c) || std::isdigit(static_cast<unsigned char>(c)); }

// Parses `text`; on a syntax error fails the test naming the line and returns false.
bool Parse(const std::string& text, Exposition* out) {
  std::istringstream in(text);
  std::string line;
  int n = 0;
  std::set<std::string> sampled_families;
  while (std::getline(in, line)) {
    ++n;
    const std::string where = "line " + std::to_string(n) + ": '" + line + "'";
    if (line.empty()) continue;
    if (line[0] == '#') {
      std::istringstream c(line.substr(1));
      std::string keyword, name, rest;
      c >> keyword >> name;
      if (keyword != "HELP" && keyword != "TYPE") continue;  // other comments are allowed.
      if (name.empty()) return ADD_FAILURE() << where << ": no metric name", false;
      if (keyword == "TYPE") {
        c >> rest;
        static const std::set<std::string> kTypes = {"counter", "gauge", "histogram", "summary",
                                                     "untyped"};
        if (!kTypes.count(rest)) return ADD_FAILURE() << where << ": unknown type", false;
        if (out->types.count(name)) return ADD_FAILURE() << where << ": second TYPE", false;
        if (sampled_families.count(name)) {
          return ADD_FAILURE() << where << ": TYPE after the family's samples", false;
        }
        out->types[name] = rest;
      }
      continue;
    }
    Sample s;
    size_t i = 0;
    if (!IsNameStart(line[0])) return ADD_FAILURE() << where << ": bad metric name", false;
    while (i < line.size() && IsNameChar(line[i])) s.name += line[i++];
    if (i < line.size() && line[i] == '{') {
      ++i;
      while (i < line.size() && line[i] != '}') {
        std::string label;
        if (!IsNameStart(line[i])) return ADD_FAILURE() << where << ": bad label name", false;
        while (i < line.size() && IsNameChar(line[i])) label += line[i++];
        if (i + 1 >= line.size() || line[i] != '=' || line[i + 1] != '"') {
          return ADD_FAILURE() << where << ": expected =\" after a label name", false;
        }
        i += 2;
        std::string value;
        while (i < line.size() && line[i] != '"') {
          if (line[i] == '\\') {
            if (i + 1 >= line.size()) return ADD_FAILURE() << where << ": bad escape", false;
            const char e = line[i + 1];
            if (e != '\\' && e != '"' && e != 'n') {
              return ADD_FAILURE() << where << ": bad escape", false;
            }
            value += e == 'n' ? '\n' : e;
            i += 2;
          } else {
            value += line[i++];
          }
        }
        if (i >= line.size()) return ADD_FAILURE() << where << ": unterminated label", false;
        ++i;  // closing quote.
        if (s.labels.count(label)) return ADD_FAILURE() << where << ": repeated label", false;
        s.labels[label] = value;
        if (i < line.size() && line[i] == ',') ++i;
      }
      if (i >= line.size()) return ADD_FAILURE() << where << ": unterminated labels", false;
      ++i;  // '}'.
    }
    if (i >= line.size() || line[i] != ' ') return ADD_FAILURE() << where << ": no value", false;
    const std::string value = line.substr(i + 1);
    if (value == "+Inf") {
      s.value = INFINITY;
    } else if (value == "-Inf") {
      s.value = -INFINITY;
    } else if (value == "NaN") {
      s.value = NAN;
    } else {
      size_t used = 0;
      try {
        s.value = std::stod(value, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != value.size()) return ADD_FAILURE() << where << ": bad value", false;
    }
    std::string family = s.name;
    for (const char* suffix : {"_bucket", "_sum", "_count"}) {
      const std::string sfx = suffix;
      if (family.size() > sfx.size() &&
          family.compare(family.size() - sfx.size(), sfx.size(), sfx) == 0 &&
          out->types.count(family.substr(0, family.size() - sfx.size())) &&
          out->types[family.substr(0, family.size() - sfx.size())] == "histogram") {
        family = family.substr(0, family.size() - sfx.size());
      }
    }
    if (!out->types.count(family)) return ADD_FAILURE() << where << ": no TYPE before it", false;
    sampled_families.insert(family);
    out->samples.push_back(std::move(s));
  }
  return true;
}

double Find(const Exposition& e, const std::string& name,
            const std::map<std::string, std::string>& labels) {
  for (const Sample& s : e.samples) {
    if (s.name == name && s.labels == labels) return s.value;
  }
  ADD_FAILURE() << "no sample " << name;
  return NAN;
}

PublishedEstimate EstimateWithTimings(double total_ms, double latency_s) {
  PublishedEstimate e;
  e.ok = true;
  e.estimate.timings.cloud_ms = 0.2 * total_ms;
  e.estimate.timings.floor_ms = 0.1 * total_ms;
  e.estimate.timings.cluster_ms = 0.1 * total_ms;
  e.estimate.timings.search_ms = 0.6 * total_ms;
  e.estimate.timings.total_ms = total_ms;
  e.queue_s = 0.001;
  e.latency_s = latency_s;
  return e;
}

TEST(HistogramTest, CumulativeBucketsSumAndCount) {
  Histogram h({0.1, 0.2, 0.4});
  for (const double v : {0.05, 0.1, 0.15, 0.3, 0.5, 2.0}) h.Observe(v);
  h.Observe(NAN);  // ignored.
  const Histogram::Snapshot s = h.Read();
  EXPECT_EQ(s.cumulative, (std::vector<std::uint64_t>{2, 3, 4}));  // 0.1 falls in le=0.1.
  EXPECT_EQ(s.count, 6u);
  EXPECT_NEAR(s.sum, 3.1, 1e-12);
  EXPECT_EQ(Histogram::ExponentialBounds(0.5, 2.0, 4), (std::vector<double>{0.5, 1, 2, 4}));
}

TEST(MetricsTest, ExpositionParsesAndCountersFollowTheDaemon) {
  DaemonMetrics metrics;
  metrics.RecordDepthEstimate(EstimateWithTimings(100.0, 0.12));
  metrics.RecordDepthEstimate(EstimateWithTimings(300.0, 0.35));
  PublishedEstimate failed;  // a frame without a floor: only queue and latency are timed.
  failed.latency_s = 0.01;
  metrics.RecordDepthEstimate(failed);
  metrics.RecordRpc("hpose.v1.PoseService/GetLatest", "OK");
  metrics.RecordRpc("hpose.v1.PoseService/GetLatest", "OK");
  metrics.RecordRpc("hpose.v1.PoseService/Estimate", "INVALID_ARGUMENT");
  metrics.ClientConnected("http_events");
  metrics.ClientConnected("grpc_call");
  metrics.ClientConnected("grpc_call");
  metrics.ClientDisconnected("grpc_call");

  PipelineStatus depth;
  depth.state = SourceState::kRunning;
  depth.frames_in = 40;
  depth.frames_estimated = 30;
  depth.frames_dropped = 7;
  depth.frames_failed = 3;
  PipelineStatus stereo;
  stereo.state = SourceState::kFinished;
  const std::string text =
      metrics.Render({{"depth", depth}, {"stereo", stereo}}, 12.5, "1.2.3 \"test\"");
  Exposition e;
  ASSERT_TRUE(Parse(text, &e)) << text;

  EXPECT_EQ(e.types.at("hposed_frames_received_total"), "counter");
  EXPECT_EQ(e.types.at("hposed_estimate_stage_seconds"), "histogram");
  EXPECT_EQ(Find(e, "hposed_frames_received_total", {{"source", "depth"}}), 40);
  EXPECT_EQ(Find(e, "hposed_frames_estimated_total", {{"source", "depth"}}), 30);
  EXPECT_EQ(Find(e, "hposed_frames_dropped_total", {{"source", "depth"}}), 7);
  EXPECT_EQ(Find(e, "hposed_frames_failed_total", {{"source", "depth"}}), 3);
  EXPECT_EQ(Find(e, "hposed_source_state", {{"source", "depth"}, {"state", "running"}}), 1);
  EXPECT_EQ(Find(e, "hposed_source_state", {{"source", "depth"}, {"state", "failed"}}), 0);
  EXPECT_EQ(Find(e, "hposed_source_state", {{"source", "stereo"}, {"state", "finished"}}), 1);
  EXPECT_EQ(
      Find(e, "hposed_rpc_total", {{"method", "hpose.v1.PoseService/GetLatest"}, {"code", "OK"}}),
      2);
  EXPECT_EQ(Find(e, "hposed_rpc_total",
                 {{"method", "hpose.v1.PoseService/Estimate"}, {"code", "INVALID_ARGUMENT"}}),
            1);
  EXPECT_EQ(Find(e, "hposed_clients_connected", {{"kind", "grpc_call"}}), 1);
  EXPECT_EQ(Find(e, "hposed_clients_connected", {{"kind", "http_events"}}), 1);
  EXPECT_EQ(Find(e, "hposed_build_info", {{"version", "1.2.3 \"test\""}}), 1);
  EXPECT_EQ(Find(e, "hposed_uptime_seconds", {}), 12.5);

  // Every stage: buckets non-decreasing, +Inf = _count; estimator stages count the two
  // estimates that succeeded, queue and latency all three.
  for (const std::string& stage : DaemonMetrics::StageNames()) {
    double previous = 0.0, inf = -1.0;
    for (const Sample& s : e.samples) {
      if (s.name != "hposed_estimate_stage_seconds_bucket" || s.labels.at("stage") != stage) {
        continue;
      }
      EXPECT_GE(s.value, previous) << stage << " le=" << s.labels.at("le");
      previous = s.value;
      if (s.labels.at("le") == "+Inf") inf = s.value;
    }
    const double count = Find(e, "hposed_estimate_stage_seconds_count", {{"stage", stage}});
    EXPECT_EQ(inf, count) << stage;
    const bool all = stage == "queue" || stage == "latency";
    EXPECT_EQ(count, all ? 3 : 2) << stage;
  }
  EXPECT_NEAR(Find(e, "hposed_estimate_stage_seconds_sum", {{"stage", "estimate"}}), 0.4, 1e-12);
  EXPECT_NEAR(Find(e, "hposed_estimate_stage_seconds_sum", {{"stage", "latency"}}), 0.48, 1e-12);
  // 0.12 s and 0.35 s: below the 0.128 s bound one latency, below 0.512 s both, plus the 0.01 s.
  EXPECT_EQ(
      Find(e, "hposed_estimate_stage_seconds_bucket", {{"stage", "latency"}, {"le", "0.128"}}), 2);
  EXPECT_EQ(
      Find(e, "hposed_estimate_stage_seconds_bucket", {{"stage", "latency"}, {"le", "0.512"}}), 3);
}

// Counts are written as whole numbers, whatever their digits: 10 and 100 frames read "10" and
// "100" (the shortest form that reads back, "1e+01" and "1e+02", is valid exposition text but
// not what a person or a line-based scraper expects of a counter); fractions stay short.
TEST(MetricsTest, CountsAreWrittenInFull) {
  DaemonMetrics metrics;
  PipelineStatus depth;
  depth.frames_in = 100;
  depth.frames_estimated = 10;
  depth.frames_dropped = 1000000;
  depth.frames_failed = 0;
  const std::string text = metrics.Render({{"depth", depth}}, 20.0, "v");
  EXPECT_NE(text.find("\nhposed_frames_received_total{source=\"depth\"} 100\n"), std::string::npos)
      << text;
  EXPECT_NE(text.find("\nhposed_frames_estimated_total{source=\"depth\"} 10\n"), std::string::npos)
      << text;
  EXPECT_NE(text.find("\nhposed_frames_dropped_total{source=\"depth\"} 1000000\n"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("\nhposed_frames_failed_total{source=\"depth\"} 0\n"), std::string::npos)
      << text;
  EXPECT_NE(text.find("\nhposed_uptime_seconds 20\n"), std::string::npos) << text;
  EXPECT_EQ(text.find("e+"), std::string::npos) << text;
  // A bucket bound keeps its shortest form.
  EXPECT_NE(text.find("le=\"0.512\""), std::string::npos) << text;
}

// The web view's connections as given, and the process's descriptors and their limit as the
// process has them (the names Prometheus's client libraries use).
TEST(MetricsTest, ConnectionsAndDescriptors) {
  DaemonMetrics metrics;
  WebConnections web;
  web.open = 7;
  web.reading = 3;
  // Descriptors opened for the test show in the count.
  std::vector<int> opened;
  for (int i = 0; i < 20; ++i) opened.push_back(dup(1));
  const auto count_fds = [] {
    int n = 0;
    for ([[maybe_unused]] const auto& entry :
         std::filesystem::directory_iterator("/proc/self/fd")) {
      ++n;
    }
    return n - 1;  // the directory's own descriptor, open while it is listed.
  };
  const int before = count_fds();
  const std::string text = metrics.Render({}, 1.0, "v", web);
  const int after = count_fds();
  for (int fd : opened) close(fd);
  Exposition e;
  ASSERT_TRUE(Parse(text, &e)) << text;
  EXPECT_EQ(e.types.at("hposed_http_connections"), "gauge");
  EXPECT_EQ(Find(e, "hposed_http_connections", {{"state", "open"}}), 7);
  EXPECT_EQ(Find(e, "hposed_http_connections", {{"state", "reading"}}), 3);
  const double fds = Find(e, "process_open_fds", {});
  EXPECT_GE(fds, std::min(before, after) - 1);  // the count's own directory may be in it.
  EXPECT_LE(fds, std::max(before, after) + 1);
  EXPECT_GE(fds, 23);
  rlimit limit{};
  ASSERT_EQ(getrlimit(RLIMIT_NOFILE, &limit), 0);
  if (limit.rlim_cur != RLIM_INFINITY) {
    EXPECT_EQ(Find(e, "process_max_fds", {}), static_cast<double>(limit.rlim_cur));
  }
}

TEST(MetricsTest, ParserRejectsMalformedText) {
  Exposition e;
  // The parser must be able to fail: a sample without a TYPE, and a broken label.
  ::testing::TestPartResultArray failures;
  {
    ::testing::ScopedFakeTestPartResultReporter reporter(
        ::testing::ScopedFakeTestPartResultReporter::INTERCEPT_ONLY_CURRENT_THREAD, &failures);
    EXPECT_FALSE(Parse("metric_without_type 1\n", &e));
    Exposition f;
    EXPECT_FALSE(Parse("# TYPE m counter\nm{a=\"x} 1\n", &f));
    Exposition g;
    EXPECT_FALSE(Parse("# TYPE m counter\nm 1x\n", &g));
  }
  EXPECT_EQ(failures.size(), 3);
}

TEST(MetricsTest, EscapesLabelValues) {
  EXPECT_EQ(EscapeLabelValue("a\\b\"c\nd"), "a\\\\b\\\"c\\nd");
}

}  // namespace
}  // namespace hpose::server
