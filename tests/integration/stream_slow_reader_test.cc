// A StreamPoses reader slower than the daemon's source: it must get the newest estimate each
// time it reads (older ones skipped and counted), every message stamped by the daemon at send.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <google/protobuf/util/time_util.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "hpose/v1/pose_service.grpc.pb.h"
#include "server/daemon.h"
#include "tests/integration/test_util.h"
#include "tests/sanitizer_build.h"

namespace hpose::server {
namespace {

using namespace std::chrono_literals;
using google::protobuf::util::TimeUtil;
namespace tu = hpose::testing_util;

double Seconds(const google::protobuf::Timestamp& t) {
  return static_cast<double>(TimeUtil::TimestampToNanoseconds(t)) * 1e-9;
}

double NowSeconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

struct Received {
  v1::PoseEstimate msg;
  double read_at = 0.0;  // client wall clock when Read returned.
};

TEST(StreamSlowReaderTest, SlowReaderGetsTheNewestEstimateWithSkipsCounted) {
  // Needs estimates published faster than the reader reads; under the sanitizers one takes
  // seconds, so nothing is ever skipped there.
  HPOSE_SKIP_IF_SANITIZED();
  const std::string dir = tu::MakeTempDir("slow_reader");
  ASSERT_TRUE(tu::SimulateFrames(dir + "/frames", 4));
  DaemonConfig config;
  config.grpc.listen = "127.0.0.1:0";
  config.source.path = dir + "/frames";
  config.source.loop = true;
  config.source.fps = 15.0;
  config.templates = {tu::TemplatePath("standing")};
  Result<std::unique_ptr<Daemon>> daemon = Daemon::Start(config);
  ASSERT_TRUE(daemon.ok()) << daemon.error().ToString();

  // A client opened as docs/API.md recommends for streaming (and as `hpose query` and the
  // Python client do): no read-ahead, so the transport does not hold estimates for it.
  grpc::ChannelArguments args;
  args.SetInt(GRPC_ARG_HTTP2_BDP_PROBE, 0);
  args.SetInt(GRPC_ARG_HTTP2_STREAM_LOOKAHEAD_BYTES, 1);
  auto stub = v1::PoseService::NewStub(grpc::CreateCustomChannel(
      "127.0.0.1:" + std::to_string((*daemon)->port()), grpc::InsecureChannelCredentials(), args));
  grpc::ClientContext ctx;
  ctx.set_deadline(std::chrono::system_clock::now() + 120s);
  auto reader = stub->StreamPoses(&ctx, v1::StreamPosesRequest());

  // The reader takes 0.8 s per message; the source publishes several estimates in that time.
  // (Without the channel settings above, gRPC's default read-ahead of 64 KiB or more holds
  // dozens of ~1 KB estimates: the reader would get every one, ever older.)
  const auto reader_period = 800ms;
  std::vector<Received> got;
  for (int i = 0; i < 6; ++i) {
    Received r;
    ASSERT_TRUE(reader->Read(&r.msg)) << "message " << i;
    r.read_at = NowSeconds();
    got.push_back(r);
    std::this_thread::sleep_for(reader_period);
  }
  ctx.TryCancel();
  v1::PoseEstimate rest;
  while (reader->Read(&rest)) {
  }

  std::uint64_t skipped_total = 0;
  for (size_t i = 0; i < got.size(); ++i) {
    const v1::PoseEstimate& m = got[i].msg;
    const double received = Seconds(m.received_time());
    const double published = Seconds(m.publish_time());
    const double sent = Seconds(m.send_time());
    std::printf("msg %zu: seq %llu skipped %llu age %.3f send->read %.3f stale %d\n", i,
                static_cast<unsigned long long>(m.sequence()),
                static_cast<unsigned long long>(m.skipped()), m.age(), got[i].read_at - sent,
                m.stale() ? 1 : 0);
    // The daemon's three clocks are in order and `age` spans arrival to send.
    EXPECT_LE(received, published + 1e-6);
    EXPECT_LE(published, sent + 1e-6);
    EXPECT_GE(m.age(), m.timings().latency());
    EXPECT_NEAR(m.age(), sent - received, 0.05);
    EXPECT_FALSE(m.stale()) << m.stale_reason();
    if (i == 0) continue;
    const v1::PoseEstimate& prev = got[i - 1].msg;
    // The 4-frame recording loops: source_time goes back only when a new source epoch starts.
    EXPECT_GE(m.source_epoch(), prev.source_epoch());
    if (m.source_time() < prev.source_time()) EXPECT_GT(m.source_epoch(), prev.source_epoch());
    // Estimates the daemon published but did not send are counted, and the frame sequence moved
    // on by at least as many.
    EXPECT_GE(m.sequence(), prev.sequence() + m.skipped() + 1);
    skipped_total += m.skipped();
    // The newest estimate when the reader came back for the previous one: sent after it read
    // message i - 2 (at most one message waits in the transport), not queued for many periods.
    if (i >= 2) {
      EXPECT_GT(sent, got[i - 2].read_at) << "message " << i << " waited in the transport";
    }
  }
  EXPECT_GT(skipped_total, 0u);
  EXPECT_GT(got.back().msg.source_epoch(), 0u);  // ~5 s of a 4-frame loop at 15 fps.
  (*daemon)->Shutdown();
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace hpose::server
